#include "app/bench_rays.h"

#include <cmath>
#include <numbers>

#include "geometry/triangle.h"

namespace sahara {

namespace {

/// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators", 2014).
uint64_t splitmix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/// Counter-based uniform floats in [0, 1): stream (seed, set, index) -> values.
struct IndexRng {
    uint64_t state;
    IndexRng(uint64_t seed, uint64_t set, uint64_t index)
        : state(splitmix64(seed ^ splitmix64(set * 0x1000003ull + index))) {}
    float next() {
        state = splitmix64(state);
        return float(state >> 40) * 0x1p-24f;
    }
};

struct Frame {
    Vec3 eye, forward, right, up;
    float tan_half_fov;
};

Frame frame_mesh(const Bounds3& b) {
    const Vec3 c = b.center();
    float r = 0.5f * length(b.extent());
    if (!(r > 0.0f)) r = 1.0f;
    const float half_fov = 20.0f * std::numbers::pi_v<float> / 180.0f;
    const Vec3 view = normalize(Vec3(0.4f, 0.3f, 1.0f));
    Frame f;
    f.eye = c + view * (1.05f * r / std::sin(half_fov));
    f.forward = -view;
    f.right = normalize(cross(f.forward, Vec3(0, 1, 0)));
    f.up = cross(f.right, f.forward);
    f.tan_half_fov = std::tan(half_fov);
    return f;
}

/// Cosine-weighted direction about unit normal n (Malley's method).
Vec3 cosine_direction(const Vec3& n, float u1, float u2) {
    const Vec3 a = std::fabs(n.x) > 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    const Vec3 t = normalize(cross(a, n)), bt = cross(n, t);
    const float phi = 2.0f * std::numbers::pi_v<float> * u1, sr = std::sqrt(u2);
    return t * (sr * std::cos(phi)) + bt * (sr * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1.0f - u2));
}

/// A primary hit: spawn point and facing unit geometric normal.
struct SurfacePoint {
    Vec3 p, n;
};

}  // namespace

BenchRaySets make_bench_rays(const TriangleMesh& mesh, const Accelerator& accel, int width, int height,
                             uint64_t seed) {
    BenchRaySets sets;
    const Bounds3 b = accel.bounds();
    const Frame f = frame_mesh(b);
    const auto count = size_t(width) * size_t(height);
    sets.primary.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const auto x = float(i % size_t(width)), y = float(i / size_t(width));
        const float sx =
            (2.0f * (x + 0.5f) / float(width) - 1.0f) * f.tan_half_fov * float(width) / float(height);
        const float sy = (1.0f - 2.0f * (y + 0.5f) / float(height)) * f.tan_half_fov;
        sets.primary[i] = Ray{f.eye, normalize(f.forward + f.right * sx + f.up * sy)};
    }
    // Primary hits (not timed; the bench traces the sets again).
    const float radius = std::max(0.5f * length(b.extent()), 1e-6f);
    std::vector<SurfacePoint> per_pixel(count);
    std::vector<char> valid(count, 0);
#pragma omp parallel for schedule(dynamic, 1024)
    for (size_t i = 0; i < count; ++i) {
        Ray r = sets.primary[i];
        Hit h;
        if (!accel.intersect(r, h) || prim_kind(h.prim) != PrimKind::triangle) continue;
        Vec3 n = triangle_geometric_normal(mesh, prim_index(h.prim));
        if (dot(n, r.dir) > 0.0f) n = -n;
        per_pixel[i] = {r.at(h.t) + n * (1e-4f * radius), n};
        valid[i] = 1;
    }
    std::vector<SurfacePoint> points;
    for (size_t i = 0; i < count; ++i)
        if (valid[i]) points.push_back(per_pixel[i]);
    if (points.empty()) return sets;
    // A square light of side `radius`, 1.5 radii above the top of the bounds.
    const Vec3 light_corner(b.center().x - 0.5f * radius, b.hi.y + 1.5f * radius,
                            b.center().z - 0.5f * radius);
    sets.diffuse.resize(count);
    sets.shadow.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const SurfacePoint& sp = points[i % points.size()];
        IndexRng d(seed, 1, i), s(seed, 2, i);
        const float u1 = d.next(), u2 = d.next();
        sets.diffuse[i] = Ray{sp.p, cosine_direction(sp.n, u1, u2)};
        const float l1 = s.next(), l2 = s.next();
        const Vec3 target = light_corner + Vec3(l1 * radius, 0.0f, l2 * radius);
        sets.shadow[i] = Ray{sp.p, target - sp.p, 0.0f, 1.0f - 1e-4f};
    }
    return sets;
}

}  // namespace sahara
