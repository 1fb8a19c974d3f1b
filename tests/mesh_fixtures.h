#pragma once
// Procedural meshes and seeded ray sets shared by the BVH, packet, triangle and loader tests.
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "math/bounds.h"
#include "math/ray.h"
#include "desc/scene_desc.h"
#include "io/mesh_utils.h"  // mesh_bounds
#include "sanitizer_build.h"

namespace sahara::test {

/// Closed icosphere: an icosahedron with each triangle split into 4, `level` times,
/// vertices pushed to the sphere; shared vertices are deduplicated (watertight topology).
inline TriangleMesh make_icosphere(int level, float radius = 1.0f, Vec3 center = {0, 0, 0}) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<Vec3> p = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    std::vector<uint32_t> idx = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                                 6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (Vec3& v : p) v = normalize(v);
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            p.push_back(normalize((p[a] + p[b]) * 0.5f));
            return mid[key] = uint32_t(p.size() - 1);
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < idx.size(); i += 3) {
            const uint32_t a = idx[i], b = idx[i + 1], c = idx[i + 2];
            const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        idx = std::move(next);
    }
    TriangleMesh m;
    m.name = "icosphere";
    for (const Vec3& v : p) m.positions.push_back(center + v * radius);
    m.indices = std::move(idx);
    return m;
}

/// The unit square [0,1]^2 at height z as an n x n grid of quads (2n^2 triangles, several
/// BVH leaves), uv = (x, y), counter-clockwise seen from +z.
inline TriangleMesh unit_grid(int n, float z, uint32_t material) {
    TriangleMesh m;
    m.name = "grid";
    m.material = material;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = float(i) / float(n), y = float(j) / float(n);
            m.positions.push_back({x, y, z});
            m.uvs.push_back({x, y});
        }
    const auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j),
                                               at(i + 1, j + 1), at(i, j + 1)});
    return m;
}

/// A closed box [-h, h]^2 x [0, thickness] with outward (counter-clockwise) faces,
/// all of material 1: a slab of glass in the volume and dispersion tests.
inline TriangleMesh make_slab(float half_width, float thickness) {
    TriangleMesh m;
    m.material = 1;
    const float a = -half_width, b = half_width;
    const Vec3 X(b - a, 0, 0), Y(0, b - a, 0), Z(0, 0, thickness);
    // Each face: a corner and two edges whose cross product points outwards.
    const Vec3 faces[6][3] = {{{a, a, thickness}, X, Y}, {{a, a, 0}, Y, X}, {{b, a, 0}, Y, Z},
                              {{a, a, 0}, Z, Y},         {{a, b, 0}, Z, X}, {{a, a, 0}, X, Z}};
    for (const auto& f : faces) {
        const auto base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {f[0], f[0] + f[1], f[0] + f[1] + f[2], f[0] + f[2]});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

/// n x n grid of tiny, separated triangles in the z = 0 plane.
inline TriangleMesh make_tiny_grid(int n, float cell = 1.0f, float size = 1e-3f) {
    TriangleMesh m;
    m.name = "tiny grid";
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const auto base = uint32_t(m.positions.size());
            const Vec3 o(float(x) * cell, float(y) * cell, 0.0f);
            m.positions.insert(m.positions.end(), {o, o + Vec3(size, 0, 0), o + Vec3(0, size, 0)});
            m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
        }
    return m;
}

/// Long thin slivers (length 10, width ~1e-4) in random orientations around the origin.
inline TriangleMesh make_slivers(int n, uint32_t seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    TriangleMesh m;
    m.name = "slivers";
    for (int i = 0; i < n; ++i) {
        const Vec3 c(u(rng), u(rng), u(rng));
        Vec3 d(u(rng), u(rng), u(rng));
        d = normalize(d) * 5.0f;
        const Vec3 w = normalize(cross(d, Vec3(u(rng), u(rng), u(rng)))) * 1e-4f;
        const auto base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {c - d, c + d, c + w});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    return m;
}

/// A small icosphere plus zero-area triangles: repeated vertices and collinear vertices.
inline TriangleMesh make_degenerate_mesh() {
    TriangleMesh m = make_icosphere(2, 1.0f);
    m.name = "degenerate";
    const auto n = uint32_t(m.positions.size());
    for (uint32_t i = 0; i + 2 < n; i += 3) {
        m.indices.insert(m.indices.end(), {i, i, i + 1});  // repeated vertex
        m.indices.insert(m.indices.end(), {i, i, i});      // a point
    }
    const auto base = uint32_t(m.positions.size());
    for (int k = 0; k < 50; ++k) {  // collinear triples through the sphere
        const float s = float(k) * 0.04f - 1.0f;
        m.positions.insert(m.positions.end(), {Vec3(s, -2, 0.1f), Vec3(s, 0, 0.1f), Vec3(s, 2, 0.1f)});
        const auto b = base + uint32_t(3 * k);
        m.indices.insert(m.indices.end(), {b, b + 1, b + 2});
    }
    return m;
}

/// A stand-in for a big real scan (the suite needs no downloaded meshes): a sphere of
/// `rings` x `segments` quads, two triangles each, on an irregular grid (every inner
/// vertex nudged), its radius displaced by smooth bumps and fine ripples. Like a scan
/// it is big, has holes (`holes` caps cut out: boundary edges), long thin triangles
/// (near the poles) and zero-area triangles: every pole row's vertices share one
/// position, so one triangle of each quad there has two equal corners. Unused vertices
/// are dropped, so the mesh's bounds are those of its triangles.
inline TriangleMesh make_scan_mesh(int rings, int segments, int holes, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    struct Wave {
        Vec3 dir;
        float freq, amp, phase;
    };
    std::vector<Wave> waves;
    for (int k = 0; k < 12; ++k)  // bumps (low frequency) to ripples (high frequency, small)
        waves.push_back({normalize(Vec3(u(rng), u(rng), u(rng)) + Vec3(1e-3f)), 1.5f + 3.0f * float(k),
                         0.08f / (1.0f + float(k)), 3.14159265f * u(rng)});
    // The radius depends on the direction only, so the pole rows keep one position each.
    auto surface = [&](Vec3 d) {
        float r = 1.0f;
        for (const Wave& w : waves) r += w.amp * std::sin(w.freq * dot(d, w.dir) + w.phase);
        return d * r;
    };
    const float pi = 3.14159265f;
    std::vector<Vec3> grid;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const bool pole = r == 0 || r == rings;
            const float theta = pi * (float(r) + (pole ? 0.0f : 0.3f * u(rng))) / float(rings);
            const float phi = 2.0f * pi * (float(s) + (pole ? 0.0f : 0.3f * u(rng))) / float(segments);
            grid.push_back(surface(
                Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi))));
        }
    std::vector<Vec3> hole_dirs;
    for (int h = 0; h < holes; ++h)
        hole_dirs.push_back(normalize(Vec3(u(rng), u(rng), u(rng)) + Vec3(1e-3f)));
    auto in_hole = [&](uint32_t a) {
        const Vec3 d = normalize(grid[a]);
        for (const Vec3& h : hole_dirs)
            if (dot(d, h) > 0.995f) return true;
        return false;
    };
    auto at = [&](int r, int s) { return uint32_t(r * segments + (s % segments)); };
    std::vector<uint32_t> tris;
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = at(r, s), b = at(r, s + 1), c = at(r + 1, s + 1), d = at(r + 1, s);
            if (in_hole(a)) continue;
            tris.insert(tris.end(), {a, c, d, a, b, c});  // counter-clockwise seen from outside
        }
    TriangleMesh m;
    m.name = "scan-like mesh";
    std::vector<uint32_t> remap(grid.size(), UINT32_MAX);
    for (uint32_t v : tris) {
        if (remap[v] == UINT32_MAX) {
            remap[v] = uint32_t(m.positions.size());
            m.positions.push_back(grid[v]);
        }
        m.indices.push_back(remap[v]);
    }
    return m;
}

/// The ~70k-triangle scan stand-in (in place of a Stanford-bunny-sized mesh) and a
/// ~120k one (past 100k triangles, for the parallel build's larger trees).
inline TriangleMesh make_scan_mesh_70k() { return make_scan_mesh(150, 240, 12, 1); }
inline TriangleMesh make_scan_mesh_120k() { return make_scan_mesh(200, 310, 8, 2); }

/// Number of triangles with two equal corners (zero area by construction).
inline size_t count_repeated_corner_triangles(const TriangleMesh& m) {
    size_t n = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        const Vec3 &a = m.positions[m.indices[3 * t]], &b = m.positions[m.indices[3 * t + 1]],
                   &c = m.positions[m.indices[3 * t + 2]];
        n += a == b || b == c || a == c;
    }
    return n;
}

/// Seeded random rays: origins uniformly in `b` grown by 50% on every side
/// (so both inside and outside), directions uniform on the sphere, except
/// every 4th ray which is axis-parallel (+-x, +-y or +-z, with exact zeros).
inline std::vector<Ray> make_random_rays(const Bounds3& b, int count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    const Vec3 e = b.extent(), lo = b.lo - e * 0.5f, size = e * 2.0f;
    std::vector<Ray> rays;
    rays.reserve(size_t(count));
    for (int i = 0; i < count; ++i) {
        Ray r;
        r.origin = lo + Vec3(u01(rng), u01(rng), u01(rng)) * size;
        if (i % 4 == 3) {
            const auto k = int(rng() % 6);
            r.dir = Vec3(0.0f);
            r.dir[k / 2] = (k % 2) ? -1.0f : 1.0f;
        } else {
            const float z = 1.0f - 2.0f * u01(rng), phi = 6.2831853f * u01(rng);
            const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
            r.dir = Vec3(s * std::cos(phi), s * std::sin(phi), z);
        }
        rays.push_back(r);
    }
    return rays;
}

/// Each triangle's bounding box, in index order (the BVH builders' input).
inline std::vector<Bounds3> triangle_boxes(const TriangleMesh& m) {
    std::vector<Bounds3> boxes;
    for (size_t i = 0; i < m.triangle_count(); ++i) {
        Bounds3 b;
        for (int k = 0; k < 3; ++k) b.extend(m.positions[m.indices[3 * i + size_t(k)]]);
        boxes.push_back(b);
    }
    return boxes;
}

}  // namespace sahara::test
