#pragma once
/// Sphere primitive. Roots are computed in double with the formulation of
/// Haines et al., "Precision Improvements for Ray/Sphere Intersection" (Ray
/// Tracing Gems, ch. 7): the discriminant from |f - (f.d)d|^2 avoids the
/// cancellation of b^2 - 4ac, and q = -b - sign(b) sqrt(disc) avoids it in the
/// roots. In float, centre-relative coordinates of a radius-1e6 sphere are
/// quantised to ~0.06 units; in double the hit lies within 1e-9 of the surface.
#include <cmath>
#include <optional>

#include "geometry/shape.h"
#include "math/bounds.h"
#include "math/ray.h"

namespace sahara {

struct Sphere {
    static constexpr bool kBounded = true;

    Vec3 center;
    float radius = 1;
    Vec3 velocity{0, 0, 0};  ///< centre moves by velocity * time (motion blur)
    uint32_t material = 0;

    Vec3 center_at(float time) const { return center + velocity * time; }
    /// Bounds over the shutter interval [t0, t1].
    Bounds3 bounds(float t0 = 0, float t1 = 0) const {
        Bounds3 b;
        Vec3 r(radius);
        b.extend(center_at(t0) - r);
        b.extend(center_at(t0) + r);
        b.extend(center_at(t1) - r);
        b.extend(center_at(t1) + r);
        return b;
    }
    /// Nearest hit in (ray.tmin, ray.tmax) with the centre at ray.time.
    std::optional<ShapeHit> intersect(const Ray& ray) const;
    bool occluded(const Ray& ray) const { return intersect(ray).has_value(); }
};
static_assert(Shape<Sphere>);

/// Whether the ray's line passes outside the sphere by more than any float error
/// could account for: a float distance test that lets nearest_root skip the
/// double computation for most rays that reach a sphere's leaf. The line's
/// distance from the centre is computed with a few float operations, each off by
/// at most a few ulps of |f| (f = origin - centre, itself off by an ulp of
/// |origin| + |centre|); the margin allows 1e-5 (about 160 ulps) of their sum.
inline bool sphere_clearly_missed(const Ray& ray, const Vec3& c, float r) {
    const Vec3 f = ray.origin - c;
    const float dd = dot(ray.dir, ray.dir);
    if (!(dd > 0.0f) || !(dd < kInfinity)) return false;  // leave odd rays to the exact test
    const Vec3 perp = f - ray.dir * (dot(f, ray.dir) / dd);
    const float scale = std::fabs(f.x) + std::fabs(f.y) + std::fabs(f.z) + std::fabs(ray.origin.x) +
                        std::fabs(ray.origin.y) + std::fabs(ray.origin.z) + std::fabs(c.x) + std::fabs(c.y) +
                        std::fabs(c.z);
    const float reach = r + 1e-5f * scale;
    return dot(perp, perp) > reach * reach;  // false for NaN
}

namespace sphere_detail {

/// Nearest root t in (ray.tmin, ray.tmax) of the ray against a sphere with the
/// given centre, in double, or a negative value if there is none.
inline double nearest_root(const Ray& ray, const Vec3& center_f, float radius_f) {
    if (sphere_clearly_missed(ray, center_f, radius_f)) return -1;
    const Vec3d o(ray.origin), d_raw(ray.dir), c(center_f);
    const double r = radius_f;
    const double dd = dot(d_raw, d_raw);
    const double inv_len = 1.0 / std::sqrt(dd);
    const Vec3d d = d_raw * inv_len;  // unit direction: t_unit = t * |dir|
    const Vec3d f = o - c;
    const double b = dot(f, d);  // half of the usual b
    const Vec3d perp = f - d * b;
    const double disc = r * r - dot(perp, perp);  // (b^2 - c) without cancellation
    if (disc < 0) return -1;
    const double sq = std::sqrt(disc);
    const double q = -b - std::copysign(sq, b);
    const double c0 = dot(f, f) - r * r;
    double t0 = q != 0 ? c0 / q : 0.0, t1 = q;
    if (t0 > t1) std::swap(t0, t1);
    const double tmin = double(ray.tmin) * std::sqrt(dd), tmax = double(ray.tmax) * std::sqrt(dd);
    if (t0 > tmin && t0 < tmax) return t0 * inv_len;
    if (t1 > tmin && t1 < tmax) return t1 * inv_len;
    return -1;
}

}  // namespace sphere_detail

inline std::optional<ShapeHit> Sphere::intersect(const Ray& ray) const {
    const double t = sphere_detail::nearest_root(ray, center_at(ray.time), radius);
    if (t < 0.0) return std::nullopt;
    return ShapeHit{float(t)};
}

}  // namespace sahara
