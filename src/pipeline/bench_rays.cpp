#include "pipeline/bench_rays.h"

#include <cmath>
#include <numbers>
#include <utility>

#include "geometry/spawn.h"
#include "render/camera.h"

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

/// The primary rays of `aim` (row-major, width x height).
std::vector<Ray> primary_rays(const Scene& scene, const Bounds3& b, int width, int height, BenchAim aim) {
    const auto count = size_t(width) * size_t(height);
    std::vector<Ray> rays(count);
    if (aim == BenchAim::scene_camera) {
        const Camera camera(scene.camera, width, height);
        for (size_t i = 0; i < count; ++i) {
            const auto x = float(i % size_t(width)), y = float(i / size_t(width));
            rays[i] = camera.generate_ray(x + 0.5f, y + 0.5f, Vec2{0.5f, 0.5f}, 0.0f);
        }
        return rays;
    }
    const Frame f = frame_mesh(b);
    for (size_t i = 0; i < count; ++i) {
        const auto x = float(i % size_t(width)), y = float(i / size_t(width));
        const float sx =
            (2.0f * (x + 0.5f) / float(width) - 1.0f) * f.tan_half_fov * float(width) / float(height);
        const float sy = (1.0f - 2.0f * (y + 0.5f) / float(height)) * f.tan_half_fov;
        rays[i] = Ray{f.eye, normalize(f.forward + f.right * sx + f.up * sy)};
    }
    return rays;
}

/// The world axis (0..2) closest to the view's up direction, and its sign.
std::pair<int, float> up_axis(const Scene& scene, int width, int height, BenchAim aim) {
    if (aim == BenchAim::frame_bounds) return {1, 1.0f};
    const Camera camera(scene.camera, width, height);
    const Vec3 top = camera.generate_ray(0.5f * float(width), 0.0f, Vec2{0.5f, 0.5f}, 0.0f).dir;
    const Vec3 bottom = camera.generate_ray(0.5f * float(width), float(height), Vec2{0.5f, 0.5f}, 0.0f).dir;
    const Vec3 up = normalize(top) - normalize(bottom);
    const int axis = max_dimension(abs(up));
    return {axis, up[axis] < 0.0f ? -1.0f : 1.0f};
}

/// The scene's first directional light, or null. Shadow rays head for it instead of the
/// square light: an interior's sun shines through the openings, and a light above the roof
/// would only measure rays stopped by the ceiling.
const LightDesc* first_sun(const Scene& scene) {
    for (const LightDesc& l : scene.lights)
        if (l.type == LightDesc::Type::directional) return &l;
    return nullptr;
}

}  // namespace

BenchRaySets make_bench_rays(const Scene& scene, const Accelerator& accel, int width, int height,
                             BenchAim aim, uint64_t seed) {
    BenchRaySets sets;
    const Bounds3 b = accel.bounds();
    sets.primary = primary_rays(scene, b, width, height, aim);
    const size_t count = sets.primary.size();
    // Primary hits (not timed; the bench traces the sets again).
    const float radius = std::max(0.5f * length(b.extent()), 1e-6f);
    std::vector<SurfacePoint> per_pixel(count);
    std::vector<char> valid(count, 0);
#pragma omp parallel for schedule(dynamic, 1024)
    for (size_t i = 0; i < count; ++i) {
        Ray r = sets.primary[i];
        Hit h;
        if (!accel.intersect(r, h)) continue;
        const SurfaceInteraction si = scene.interact(r, h);  // ng: unit, facing the ray
        if (!is_finite(si.ng) || !is_finite(si.p)) continue;
        per_pixel[i] = aim == BenchAim::frame_bounds
                           ? SurfacePoint{r.at(h.t) + si.ng * (1e-4f * radius), si.ng}
                           : SurfacePoint{offset_ray_origin(si.p, si.ng), si.ng};
        valid[i] = 1;
    }
    std::vector<SurfacePoint> points;
    for (size_t i = 0; i < count; ++i)
        if (valid[i]) points.push_back(per_pixel[i]);
    if (points.empty()) return sets;
    // A square light of side `radius`, 1.5 radii beyond the bounds along the up axis
    // (+y when framing the bounds).
    const auto [axis, sign] = up_axis(scene, width, height, aim);
    const int au = (axis + 2) % 3, av = (axis + 1) % 3;  // y up: u = x, v = z
    Vec3 light_corner(0.0f);
    light_corner[axis] = sign > 0.0f ? b.hi[axis] + 1.5f * radius : b.lo[axis] - 1.5f * radius;
    light_corner[au] = b.center()[au] - 0.5f * radius;
    light_corner[av] = b.center()[av] - 0.5f * radius;
    const LightDesc* sun = aim == BenchAim::scene_camera ? first_sun(scene) : nullptr;
    sets.diffuse.resize(count);
    sets.shadow.resize(count);
    for (size_t i = 0; i < count; ++i) {
        const SurfacePoint& sp = points[i % points.size()];
        IndexRng d(seed, 1, i), s(seed, 2, i);
        const float u1 = d.next(), u2 = d.next();
        sets.diffuse[i] = Ray{sp.p, cosine_direction(sp.n, u1, u2)};
        if (sun) {
            sets.shadow[i] = Ray{sp.p, -normalize(sun->direction)};
            continue;
        }
        const float l1 = s.next(), l2 = s.next();
        Vec3 target = light_corner;
        target[au] += l1 * radius;
        target[av] += l2 * radius;
        sets.shadow[i] = Ray{sp.p, target - sp.p, 0.0f, 1.0f - 1e-4f};
    }
    return sets;
}

}  // namespace sahara
