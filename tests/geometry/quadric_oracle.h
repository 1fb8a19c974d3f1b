#pragma once
// The quadric tests' oracle: each shape described again from its named parameters
// and evaluated in long double, a brute-force root search over it, and random
// instances and rays (test_quadric*.cpp).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "base/error.h"
#include "geometry/quadric.h"
#include "geometry/spawn.h"
#include "math/rng.h"
#include "math/sampling.h"
#include "sanitizer_build.h"

namespace sahara::quadric_test {

using test::kSanitized;

using LD = long double;
using VL = TVec3<long double>;

inline Ray make_ray(Vec3 o, Vec3 d, float tmin = 0.0f, float tmax = kInfinity) {
    return Ray{o, d, tmin, tmax, 0.0f};
}

/// Independent description of a shape, evaluated in long double straight from
/// the named parameters (not from the quadric's canonical frame): the oracle.
struct Oracle {
    QuadricForm form = QuadricForm::general;
    VL origin, axis;  ///< base / apex / vertex / centre; unit axis
    LD radius = 0, height = 0, waist = 0, tan_angle = 0;
    VL radii;
    bool capped = false;
    std::array<LD, 10> k{};
    VL lo, hi;                                         ///< general: clip box (pre-transform)
    LD rot[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  ///< user rotation
    VL trans;                                          ///< user translation
    LD scale = 1;                                      ///< size of the shape, for tolerances

    /// Pre-transform coordinates of world point p (the user transform is rigid).
    VL local(const VL& p) const {
        const VL v = p - trans;
        return {rot[0][0] * v.x + rot[1][0] * v.y + rot[2][0] * v.z,
                rot[0][1] * v.x + rot[1][1] * v.y + rot[2][1] * v.z,
                rot[0][2] * v.x + rot[1][2] * v.y + rot[2][2] * v.z};
    }
    VL world_vector(const VL& v) const {
        return {rot[0][0] * v.x + rot[0][1] * v.y + rot[0][2] * v.z,
                rot[1][0] * v.x + rot[1][1] * v.y + rot[1][2] * v.z,
                rot[2][0] * v.x + rot[2][1] * v.y + rot[2][2] * v.z};
    }
    LD f(const VL& pw) const {
        const VL q = local(pw);
        if (form == QuadricForm::general)
            return k[0] * q.x * q.x + k[1] * q.y * q.y + k[2] * q.z * q.z + k[3] * q.x * q.y +
                   k[4] * q.x * q.z + k[5] * q.y * q.z + k[6] * q.x + k[7] * q.y + k[8] * q.z + k[9];
        const VL v = q - origin;
        if (form == QuadricForm::ellipsoid) {
            const VL u = v / radii;
            return dot(u, u) - 1;
        }
        const LD h = dot(v, axis), perp2 = dot(v, v) - h * h;
        switch (form) {
            case QuadricForm::cylinder:
                return perp2 - radius * radius;
            case QuadricForm::cone:
                return perp2 - tan_angle * tan_angle * h * h;
            case QuadricForm::paraboloid:
                return perp2 - radius * radius / height * h;
            default: {
                const LD half = height / 2;
                return perp2 - waist * waist - (radius * radius - waist * waist) / (half * half) * h * h;
            }
        }
    }
    /// Central differences are exact for a quadratic (up to rounding).
    VL grad(const VL& p) const {
        const LD e = scale * 1e-4L;
        return VL(f(p + VL(e, 0, 0)) - f(p - VL(e, 0, 0)), f(p + VL(0, e, 0)) - f(p - VL(0, e, 0)),
                  f(p + VL(0, 0, e)) - f(p - VL(0, 0, e))) /
               (2 * e);
    }
    /// Distance-like measure of how far p is from f = 0.
    LD surface_error(const VL& p) const { return std::fabs(f(p)) / length(grad(p)); }
    /// >= 0 inside the clip range, < 0 outside (in length units).
    LD clip_margin(const VL& pw) const {
        const VL q = local(pw);
        if (form == QuadricForm::ellipsoid) return 1e30L;
        if (form == QuadricForm::general) return std::min(min_component(q - lo), min_component(hi - q));
        const LD h = dot(q - origin, axis);
        switch (form) {
            case QuadricForm::cylinder:
            case QuadricForm::cone:
                return std::min(h, height - h);
            case QuadricForm::paraboloid:
                return height - h;
            default:
                return height / 2 - std::fabs(h);
        }
    }
    int cap_count() const { return capped ? (form == QuadricForm::cylinder ? 2 : 1) : 0; }
    /// Cap i: height along the axis, radius, outward normal (pre-transform).
    void cap(int i, LD& h, LD& r, VL& n) const {
        if (form == QuadricForm::cylinder && i == 0) {
            h = 0;
            r = radius;
            n = -axis;
            return;
        }
        h = height;
        r = form == QuadricForm::cone ? height * tan_angle : radius;
        n = axis;
    }
};

/// One root of the brute-force search with what makes it delicate.
struct BfRoot {
    LD t = -1;
    bool found = false;
    bool marginal = false;  ///< grazing, at a clip edge, at a cap rim, or at tmin/tmax
};

struct BruteForce {
    const Oracle& o;
    int steps;

    /// Slab test of the ray against a box (long double).
    static bool clip_to_box(const VL& org, const VL& d, const Bounds3& b, LD& t0, LD& t1) {
        for (int k = 0; k < 3; ++k) {
            if (d[k] == 0) {
                if (org[k] < b.lo[k] || org[k] > b.hi[k]) return false;
                continue;
            }
            LD a = (LD(b.lo[k]) - org[k]) / d[k], c = (LD(b.hi[k]) - org[k]) / d[k];
            if (a > c) std::swap(a, c);
            t0 = std::max(t0, a);
            t1 = std::min(t1, c);
        }
        return t0 <= t1;
    }

    bool is_marginal(const VL& d, LD t, const Ray& ray, LD cosang, LD margin) const {
        const LD dl = length(d), tol = 1e-5L * o.scale;
        return cosang < 0.01L || std::fabs(margin) < tol || std::fabs(t - LD(ray.tmin)) * dl < tol ||
               (std::isfinite(ray.tmax) && std::fabs(t - LD(ray.tmax)) * dl < tol);
    }

    /// Sign-change scan of f along the ray inside the (enlarged) bounds, each
    /// bracket refined by bisection; cap disks are plane tests.
    BfRoot first_hit(const Ray& ray, const Bounds3& bounds) const {
        const VL org(ray.origin), d(ray.dir);
        Bounds3 big = bounds;
        const Vec3 pad = bounds.extent() * 0.05f + Vec3(1e-6f);
        big.lo = big.lo - pad;
        big.hi = big.hi + pad;
        LD t0 = ray.tmin, t1 = std::isfinite(ray.tmax) ? LD(ray.tmax) : 1e30L;
        BfRoot best;
        if (!clip_to_box(org, d, big, t0, t1)) return best;
        auto consider = [&](LD t, LD cosang, LD margin) {
            if (t <= LD(ray.tmin) || t >= LD(ray.tmax)) return;
            const bool marg = is_marginal(d, t, ray, cosang, margin);
            if (margin < -1e-5L * o.scale) return;  // outside the clip range
            if (!best.found || t < best.t) best = {t, true, marg};
        };
        LD prev_t = t0, prev_f = o.f(org + d * t0);
        for (int i = 1; i <= steps; ++i) {
            const LD t = t0 + (t1 - t0) * LD(i) / LD(steps), ft = o.f(org + d * t);
            if ((prev_f < 0) != (ft < 0) || ft == 0) {
                LD a = prev_t, b = t, fa = prev_f;
                for (int it = 0; it < 80 && a < b; ++it) {
                    const LD m = 0.5L * (a + b), fm = o.f(org + d * m);
                    if ((fa < 0) == (fm < 0)) {
                        a = m;
                        fa = fm;
                    } else {
                        b = m;
                    }
                }
                const LD tr = 0.5L * (a + b);
                const VL p = org + d * tr, g = o.grad(p);
                consider(tr, std::fabs(dot(normalize(g), normalize(d))), o.clip_margin(p));
            }
            prev_t = t;
            prev_f = ft;
        }
        for (int c = 0; c < o.cap_count(); ++c) {
            LD h, r;
            VL n;
            o.cap(c, h, r, n);
            const VL ol = o.local(org), dl = o.local(org + d) - ol;
            const LD denom = dot(dl, o.axis);
            if (denom == 0) continue;
            const LD t = (h - dot(ol - o.origin, o.axis)) / denom;
            const VL v = ol + dl * t - o.origin;
            const LD hh = dot(v, o.axis), rad = std::sqrt(std::max(LD(0), dot(v, v) - hh * hh));
            consider(t, std::fabs(denom) / length(dl), r - rad);
        }
        return best;
    }
};

inline Mat4 random_rigid(Pcg32& rng, float offset) {
    Mat4 r = Mat4::rotate_euler(
        Vec3d(Vec3(360.0f * rng.next_float(), 360.0f * rng.next_float(), 360.0f * rng.next_float())));
    return Mat4::translate(Vec3d(offset * (2 * rng.next_float() - 1), offset * (2 * rng.next_float() - 1),
                                 offset * (2 * rng.next_float() - 1))) *
           r;
}

inline Vec3 random_unit(Pcg32& rng) { return sample_uniform_sphere({rng.next_float(), rng.next_float()}); }

/// A random instance of `form` of size ~scale, displaced by up to `offset`,
/// with a random rigid user transform; fills the matching oracle.
inline Quadric make_instance(QuadricForm form, Pcg32& rng, float scale, float offset, bool capped,
                             Oracle& o) {
    const Mat4 user = random_rigid(rng, offset);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) o.rot[i][j] = LD(user.m[size_t(i)][size_t(j)]);
    o.trans = VL(LD(user.m[0][3]), LD(user.m[1][3]), LD(user.m[2][3]));
    o.form = form;
    o.capped = capped && (form == QuadricForm::cylinder || form == QuadricForm::cone);
    o.scale = scale;
    auto u = [&](float a, float b) { return a + (b - a) * rng.next_float(); };
    const Vec3 origin = random_unit(rng) * (0.5f * scale);
    const Vec3 axis = random_unit(rng) * u(0.5f, 2.0f);
    o.origin = VL(origin);
    o.axis = normalize(VL(axis));
    switch (form) {
        case QuadricForm::ellipsoid: {
            const Vec3 radii(scale * u(0.3f, 1), scale * u(0.3f, 1), scale * u(0.3f, 1));
            o.radii = VL(radii);
            return make_ellipsoid(origin, radii, user);
        }
        case QuadricForm::cylinder: {
            const float r = scale * u(0.3f, 1), h = scale * u(0.3f, 1);
            o.radius = r;
            o.height = h;
            return make_cylinder(origin, axis, r, h, capped, user);
        }
        case QuadricForm::cone: {
            const float angle = u(10, 70), h = scale * u(0.5f, 1);
            o.tan_angle = std::tan(LD(angle) * std::numbers::pi_v<long double> / 180);
            o.height = h;
            return make_cone(origin, axis, angle, h, capped, user);
        }
        case QuadricForm::paraboloid: {
            const float r = scale * u(0.3f, 1), h = scale * u(0.3f, 1);
            o.radius = r;
            o.height = h;
            return make_paraboloid(origin, axis, r, h, user);
        }
        case QuadricForm::hyperboloid: {
            const float w = scale * u(0.2f, 0.5f), r = w * u(1.2f, 3), h = scale * u(0.5f, 1);
            o.radius = r;
            o.waist = w;
            o.height = h;
            return make_hyperboloid(origin, axis, r, w, h, user);
        }
        case QuadricForm::general:
            break;
    }
    // General: a few shapes that no named form covers, scaled by `scale`:
    // f(p / s) * s² keeps the second-order terms and scales the others.
    static const std::array<std::array<double, 10>, 3> kShapes = {{
        {1, -1, 0, 0, 0, 0, 0, 0, -1, 0},       // saddle z = x² - y²
        {-1, -1, 1, 0, 0, 0, 0, 0, 0, -0.25},   // two-sheet hyperboloid
        {1, 2, 3, 0.5, 0, 0.7, 0.1, 0, 0, -1},  // tilted ellipsoid with cross terms
    }};
    std::array<double, 10> c = kShapes[rng.next_u32() % 3];
    const double s = scale;
    for (int i = 6; i < 9; ++i) c[size_t(i)] *= s;
    c[9] *= s * s;
    const Bounds3 box{Vec3(-scale, -0.8f * scale, -scale), Vec3(0.9f * scale, scale, 0.7f * scale)};
    for (int i = 0; i < 10; ++i) o.k[size_t(i)] = LD(c[size_t(i)]);
    o.lo = VL(box.lo);
    o.hi = VL(box.hi);
    return make_general_quadric(c, box, user);
}

/// A random ray around the instance: half aimed at its bounds, some along its
/// axis (the near-linear case), some with a finite tmax.
inline Ray random_ray(Pcg32& rng, const Bounds3& b, const Oracle& o) {
    const Vec3 c = b.center(), e(max_component(b.extent()));
    auto in_box = [&](float spread) {
        return c +
               Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * e * spread;
    };
    const Vec3 org = in_box(3.0f);
    Vec3 dir;
    const float kind = rng.next_float();
    if (kind < 0.25f)
        dir = random_unit(rng);
    else if (kind < 0.9f)
        dir = in_box(1.2f) - org;
    else
        dir = Vec3(o.world_vector(o.axis)) * (rng.next_float() < 0.5f ? -1.0f : 1.0f);
    dir = dir * (0.5f + 1.5f * rng.next_float());
    Ray ray = make_ray(org, dir);
    if (rng.next_float() < 0.1f) ray.tmax = 3.0f * e.x * rng.next_float() / length(dir);
    return ray;
}

inline const char* form_name(QuadricForm f) {
    switch (f) {
        case QuadricForm::ellipsoid:
            return "ellipsoid";
        case QuadricForm::cylinder:
            return "cylinder";
        case QuadricForm::cone:
            return "cone";
        case QuadricForm::paraboloid:
            return "paraboloid";
        case QuadricForm::hyperboloid:
            return "hyperboloid";
        case QuadricForm::general:
            return "general";
    }
    return "?";
}

}  // namespace sahara::quadric_test
