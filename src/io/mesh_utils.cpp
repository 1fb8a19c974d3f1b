#include "io/mesh_utils.h"

#include <numeric>

namespace sahara {

Vec3d newell_normal(std::span<const Vec3> polygon) {
    Vec3d n(0.0);
    const size_t count = polygon.size();
    for (size_t i = 0; i < count; ++i) {
        const Vec3d a(polygon[i]), b(polygon[(i + 1) % count]);
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

namespace {

struct P2 {
    double x, y;
};

/// Twice the signed area of 2-D triangle (a, b, c); positive when counter-clockwise.
double orient(const P2& a, const P2& b, const P2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Point p inside or on the boundary of counter-clockwise triangle (a, b, c).
bool in_triangle(const P2& p, const P2& a, const P2& b, const P2& c) {
    return orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0;
}

bool same(const P2& a, const P2& b) { return a.x == b.x && a.y == b.y; }

/// Projects the polygon onto the coordinate plane most parallel to it, oriented
/// so that the polygon runs counter-clockwise there.
std::vector<P2> project(std::span<const Vec3> polygon, const Vec3d& normal) {
    const int axis = max_dimension(abs(normal));
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double sign = normal[axis] < 0 ? -1.0 : 1.0;
    std::vector<P2> pts(polygon.size());
    for (size_t i = 0; i < polygon.size(); ++i)
        pts[i] = {sign * double(polygon[i][u]), double(polygon[i][v])};
    return pts;
}

/// Ear test (Meisters' two-ears theorem): corner `i` is convex and no other
/// remaining vertex lies in triangle (prev, i, next).
bool is_ear(const std::vector<P2>& pts, const std::vector<uint32_t>& prev, const std::vector<uint32_t>& next,
            uint32_t i) {
    const P2 &a = pts[prev[i]], &b = pts[i], &c = pts[next[i]];
    if (orient(a, b, c) <= 0) return false;
    for (uint32_t j = next[next[i]]; j != prev[i]; j = next[j]) {
        const P2& p = pts[j];
        if (same(p, a) || same(p, b) || same(p, c)) continue;
        if (in_triangle(p, a, b, c)) return false;
    }
    return true;
}

}  // namespace

void triangulate_polygon(std::span<const Vec3> polygon, std::vector<uint32_t>& out) {
    const auto n = uint32_t(polygon.size());
    if (n < 3) return;
    const Vec3d normal = newell_normal(polygon);
    if (n == 3 || length_squared(normal) == 0.0) {
        for (uint32_t i = 1; i + 1 < n; ++i) out.insert(out.end(), {0u, i, i + 1});  // flat fan
        return;
    }
    const std::vector<P2> pts = project(polygon, normal);
    std::vector<uint32_t> prev(n), next(n);
    for (uint32_t i = 0; i < n; ++i) {
        prev[i] = (i + n - 1) % n;
        next[i] = (i + 1) % n;
    }
    uint32_t remaining = n, i = 0, misses = 0;
    while (remaining > 3) {
        // After a full lap without an ear the rest is not simple (self-intersecting
        // or collinear): clip the current corner anyway so the count stays n - 2.
        if (misses > remaining || is_ear(pts, prev, next, i)) {
            out.insert(out.end(), {prev[i], i, next[i]});
            next[prev[i]] = next[i];
            prev[next[i]] = prev[i];
            i = prev[i];
            --remaining;
            misses = 0;
        } else {
            i = next[i];
            ++misses;
        }
    }
    out.insert(out.end(), {prev[i], i, next[i]});
}

Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = cross(b - a, c - a);
    const float len = length(n);
    return len > 0.0f ? n / len : Vec3(0.0f);
}

bool is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
    return length_squared(cross(b - a, c - a)) == 0.0f;
}

size_t remove_degenerate(TriangleMesh& mesh) {
    const size_t count = mesh.triangle_count();
    const bool per_triangle = !mesh.material_ids.empty();
    size_t kept = 0;
    for (size_t t = 0; t < count; ++t) {
        const uint32_t* idx = &mesh.indices[3 * t];
        if (is_degenerate(mesh.positions[idx[0]], mesh.positions[idx[1]], mesh.positions[idx[2]])) continue;
        for (int k = 0; k < 3; ++k) mesh.indices[3 * kept + size_t(k)] = idx[k];
        if (per_triangle) mesh.material_ids[kept] = mesh.material_ids[t];
        ++kept;
    }
    mesh.indices.resize(3 * kept);
    if (per_triangle) mesh.material_ids.resize(kept);
    return count - kept;
}

void transform_mesh(TriangleMesh& mesh, const Mat4& world_from_model) {
    for (Vec3& p : mesh.positions) p = world_from_model.apply_point(p);
    for (Vec3& n : mesh.normals) n = world_from_model.apply_normal(n);
    const bool mirrors = world_from_model.determinant3() < 0;
    for (auto& t : mesh.tangents) {
        Vec3 v = world_from_model.apply_vector({t[0], t[1], t[2]});
        if (length_squared(v) > 0.0f) v = normalize(v);
        // A mirror flips the bitangent cross(n, t) relative to the mapped uv direction.
        t = {v.x, v.y, v.z, mirrors ? -t[3] : t[3]};
    }
    if (mirrors)
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
}

Bounds3 mesh_bounds(const TriangleMesh& mesh) {
    Bounds3 b;
    for (uint32_t i : mesh.indices) b.extend(mesh.positions[i]);
    return b;
}

}  // namespace sahara
