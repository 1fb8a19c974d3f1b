#include <doctest/doctest.h>

#include <array>
#include <string>
#include <cmath>
#include <numbers>

#include "base/error.h"
#include "geometry/quadric.h"
#include "geometry/spawn.h"
#include "math/rng.h"
#include "math/sampling.h"

using namespace sahara;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

using LD = long double;
using VL = TVec3<long double>;

Ray make_ray(Vec3 o, Vec3 d, float tmin = 0.0f, float tmax = kInfinity) {
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

Mat4 random_rigid(Pcg32& rng, float offset) {
    Mat4 r = Mat4::rotate_euler(
        Vec3d(Vec3(360.0f * rng.next_float(), 360.0f * rng.next_float(), 360.0f * rng.next_float())));
    return Mat4::translate(Vec3d(offset * (2 * rng.next_float() - 1), offset * (2 * rng.next_float() - 1),
                                 offset * (2 * rng.next_float() - 1))) *
           r;
}

Vec3 random_unit(Pcg32& rng) { return sample_uniform_sphere({rng.next_float(), rng.next_float()}); }

/// A random instance of `form` of size ~scale, displaced by up to `offset`,
/// with a random rigid user transform; fills the matching oracle.
Quadric make_instance(QuadricForm form, Pcg32& rng, float scale, float offset, bool capped, Oracle& o) {
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
Ray random_ray(Pcg32& rng, const Bounds3& b, const Oracle& o) {
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

struct FormStats {
    int rays = 0, hits = 0, explained = 0, unexplained = 0, off_surface = 0, bad_normal = 0;
};

/// Checks the implementation's hit, its surface() data and normal() against the oracle.
void check_hit(const Quadric& q, const Oracle& o, const Ray& ray, const QuadricHit& h, FormStats& st) {
    const VL org(ray.origin), d(ray.dir);
    const VL p = org + d * LD(h.t);
    const QuadricSurface s = q.surface(ray, h);
    const LD tol = 1e-5L * o.scale;
    const VL ps(s.p);
    const LD quant = 4 * LD(std::numeric_limits<float>::epsilon()) * LD(max_component(abs(s.p)));
    if (h.part == QuadricPart::side) {
        const VL g = normalize(o.grad(p));
        if (o.surface_error(p) > tol || o.clip_margin(p) < -tol || o.surface_error(ps) > tol + quant)
            ++st.off_surface;
        if (dot(VL(s.n), g) < 0.9999L || s.front_face != (dot(d, g) < 0)) ++st.bad_normal;
        if (dot(VL(q.normal(s.p)), g) < 0.999L) ++st.bad_normal;
        if (!q.bounds().contains(s.p)) ++st.off_surface;
    } else {
        LD hc, r;
        VL n;
        o.cap(h.part == QuadricPart::bottom_cap ? 0 : 1, hc, r, n);
        const VL v = o.local(p) - o.origin;
        const LD hh = dot(v, o.axis), rad = std::sqrt(std::max(LD(0), dot(v, v) - hh * hh));
        if (std::fabs(hh - hc) > tol || rad > r + tol) ++st.off_surface;
        if (dot(VL(s.n), o.world_vector(n)) < 0.9999L) ++st.bad_normal;
    }
}

FormStats run_brute_force(QuadricForm form, uint64_t seed, int instances, int rays_per_instance) {
    Pcg32 rng(seed);
    FormStats st;
    for (int inst = 0; inst < instances; ++inst) {
        Oracle o;
        const float scale = std::pow(10.0f, -2.0f + 5.0f * rng.next_float());
        const float offset = scale * std::pow(10.0f, 3.0f * rng.next_float() - 1.0f);
        const Quadric q = make_instance(form, rng, scale, offset, inst % 2 == 1, o);
        const BruteForce bf{o, 512};
        for (int i = 0; i < rays_per_instance; ++i) {
            const Ray ray = random_ray(rng, q.bounds(), o);
            const QuadricHit h = q.intersect(ray);
            const BfRoot b = bf.first_hit(ray, q.bounds());
            ++st.rays;
            if (h.hit()) {
                ++st.hits;
                check_hit(q, o, ray, h, st);
            }
            if (!h.hit() && !b.found) continue;
            const LD dl = length(VL(ray.dir)), tol = 1e-5L * o.scale;
            if (h.hit() && b.found && std::fabs(LD(h.t) - b.t) * dl < tol) continue;
            // A disagreement is acceptable only where the answer is ill-conditioned.
            bool ok = b.found && b.marginal;
            if (!ok && h.hit()) {
                const VL p = VL(ray.origin) + VL(ray.dir) * LD(h.t);
                const LD cosang = h.part == QuadricPart::side
                                      ? std::fabs(dot(normalize(o.grad(p)), normalize(VL(ray.dir))))
                                      : LD(1);
                ok = cosang < 0.01L || std::fabs(o.clip_margin(p)) < 1e-4L * o.scale;
            }
            if (ok)
                ++st.explained;
            else if (++st.unexplained <= 5) {
                MESSAGE("mismatch: form ", int(form), " inst ", inst, " ray ", i, " impl t ", h.t, " part ",
                        int(h.part), " bf t ", double(b.t), " found ", b.found);
            }
        }
    }
    return st;
}

const char* form_name(QuadricForm f) {
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

}  // namespace

TEST_CASE("quadric: hand-checked cases") {
    SUBCASE("cylinder: side from outside and inside, axis-parallel rays, caps") {
        const Quadric open = make_cylinder({0, 0, 0}, {0, 0, 3}, 1, 2, false);
        QuadricHit h = open.intersect(make_ray({-5, 0, 1}, {1, 0, 0}));
        CHECK(h.t == doctest::Approx(4.0f));
        CHECK(open.surface(make_ray({-5, 0, 1}, {1, 0, 0}), h).front_face);
        h = open.intersect(make_ray({0, 0, 1}, {2, 0, 0}));
        CHECK(h.t == doctest::Approx(0.5f));
        const QuadricSurface s = open.surface(make_ray({0, 0, 1}, {2, 0, 0}), h);
        CHECK_FALSE(s.front_face);
        CHECK(s.n.x == doctest::Approx(1.0f));
        CHECK(s.uv.y == doctest::Approx(0.5f));
        // a = 0 exactly: along the axis an open tube is missed, a capped one hit on the cap.
        CHECK_FALSE(open.intersect(make_ray({0, 0, -1}, {0, 0, 1})).hit());
        const Quadric closed = make_cylinder({0, 0, 0}, {0, 0, 1}, 1, 2, true);
        h = closed.intersect(make_ray({0.5f, 0, -1}, {0, 0, 1}));
        CHECK(h.t == doctest::Approx(1.0f));
        CHECK(h.part == QuadricPart::bottom_cap);
        CHECK(closed.surface(make_ray({0.5f, 0, -1}, {0, 0, 1}), h).n.z == doctest::Approx(-1.0f));
        h = closed.intersect(make_ray({0.5f, 0, 1}, {0, 0, 1}));
        CHECK(h.t == doctest::Approx(1.0f));
        CHECK(h.part == QuadricPart::top_cap);
    }
    SUBCASE("the first root is clipped away: the second one counts") {
        const Quadric open = make_cylinder({0, 0, 0}, {0, 0, 1}, 1, 2, false);
        // Enters the infinite cylinder at z = 3 (above the top), leaves at z = 1.
        const QuadricHit h = open.intersect(make_ray({-3, 0, 5}, {1, 0, -1}));
        CHECK(h.t == doctest::Approx(4.0f));
        CHECK_FALSE(open.surface(make_ray({-3, 0, 5}, {1, 0, -1}), h).front_face);
    }
    SUBCASE("cone, paraboloid (linear case), hyperboloid, ellipsoid, general") {
        const Quadric cone = make_cone({0, 0, 0}, {0, 0, 1}, 45, 1, false);
        CHECK(cone.intersect(make_ray({-2, 0, 0.5f}, {1, 0, 0})).t == doctest::Approx(1.5f));
        CHECK_FALSE(cone.intersect(make_ray({-2, 0, -0.5f}, {1, 0, 0})).hit());  // the other nappe is clipped
        const Quadric para = make_paraboloid({0, 0, 0}, {0, 0, 1}, 1, 1);
        const QuadricHit hp = para.intersect(make_ray({0.5f, 0, 5}, {0, 0, -1}));
        CHECK(hp.t == doctest::Approx(4.75f));
        CHECK_FALSE(para.surface(make_ray({0.5f, 0, 5}, {0, 0, -1}), hp).front_face);
        const Quadric hyp = make_hyperboloid({0, 0, 0}, {0, 0, 1}, 2, 1, 2);
        CHECK(hyp.intersect(make_ray({-5, 0, 0}, {1, 0, 0})).t == doctest::Approx(4.0f));
        CHECK(hyp.intersect(make_ray({-5, 0, 0.5f}, {1, 0, 0})).t == doctest::Approx(5.0 - std::sqrt(1.75)));
        const Quadric ell = make_ellipsoid({1, 2, 3}, {1, 2, 3});
        CHECK(ell.intersect(make_ray({1, 2, -10}, {0, 0, 1})).t == doctest::Approx(10.0f));
        CHECK(ell.intersect(make_ray({1, -10, 3}, {0, 1, 0})).t == doctest::Approx(10.0f));
        CHECK(ell.bounds().contains(Bounds3{{0, 0, 0}, {2, 4, 6}}));
        // Saddle z = x² - y² in [-1,1]³: straight down through (0.5, 0) lands at z = 0.25.
        const Quadric saddle =
            make_general_quadric({1, -1, 0, 0, 0, 0, 0, 0, -1, 0}, {{-1, -1, -1}, {1, 1, 1}});
        CHECK(saddle.intersect(make_ray({0.5f, 0, 3}, {0, 0, -1})).t == doctest::Approx(2.75f));
        CHECK_FALSE(saddle.intersect(make_ray({3, 0, 3}, {0, 0, -1})).hit());
    }
    SUBCASE("tmin and tmax bound the interval") {
        const Quadric ell = make_ellipsoid({0, 0, 0}, {1, 1, 1});
        CHECK_FALSE(ell.intersect(make_ray({0, 0, -5}, {0, 0, 1}, 0, 3.9f)).hit());
        CHECK(ell.intersect(make_ray({0, 0, -5}, {0, 0, 1}, 4.5f)).t == doctest::Approx(6.0f));
    }
}

TEST_CASE("quadric: factories reject bad parameters") {
    CHECK_THROWS_AS(make_ellipsoid({0, 0, 0}, {1, 0, 1}), InputError);
    CHECK_THROWS_AS(make_cylinder({0, 0, 0}, {0, 0, 0}, 1, 1, false), InputError);
    CHECK_THROWS_AS(make_cylinder({0, 0, 0}, {0, 0, 1}, -1, 1, false), InputError);
    CHECK_THROWS_AS(make_cone({0, 0, 0}, {0, 0, 1}, 90, 1, false), InputError);
    CHECK_THROWS_AS(make_paraboloid({0, 0, 0}, {0, 0, 1}, 1, 0), InputError);
    CHECK_THROWS_AS(make_hyperboloid({0, 0, 0}, {0, 0, 1}, 0.5f, 1, 1), InputError);
    CHECK_THROWS_AS(make_general_quadric({0, 0, 0, 0, 0, 0, 0, 0, 0, 1}, {{-1, -1, -1}, {1, 1, 1}}),
                    InputError);
    CHECK_THROWS_AS(make_general_quadric({1, 1, 1, 0, 0, 0, 0, 0, 0, -1}, Bounds3{}), InputError);
    CHECK_THROWS_AS(make_ellipsoid({0, 0, 0}, {1, 1, 1}, Mat4::scale({1, 0, 1})), InputError);
}

namespace {

/// 100k rays per form (4 instances of sizes 1e-2..1e3, offsets up to 1e2 x size)
/// against a sign-change scan of the long-double implicit function.
void check_against_brute_force(QuadricForm form) {
    const int per_instance = kSanitized ? 2500 : 25000;
    const FormStats st = run_brute_force(form, 1000 + uint64_t(form), 4, per_instance);
    INFO("rays ", st.rays, " hits ", st.hits, " ill-conditioned ", st.explained);
    CHECK(st.hits > st.rays / 10);
    CHECK(st.unexplained == 0);
    CHECK(st.off_surface == 0);
    CHECK(st.bad_normal == 0);
    CHECK(st.explained <= st.rays / 200);
}

}  // namespace

TEST_CASE("quadric: ellipsoid agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::ellipsoid);
}
TEST_CASE("quadric: cylinder agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::cylinder);
}
TEST_CASE("quadric: cone agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::cone);
}
TEST_CASE("quadric: paraboloid agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::paraboloid);
}
TEST_CASE("quadric: hyperboloid agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::hyperboloid);
}
TEST_CASE("quadric: general quadric agrees with brute-force root finding") {
    check_against_brute_force(QuadricForm::general);
}

TEST_CASE("quadric: rays spawned from a hit towards either side never re-hit at t ~ 0") {
    const int per_instance = kSanitized ? 500 : 5000;
    for (QuadricForm form : {QuadricForm::ellipsoid, QuadricForm::cylinder, QuadricForm::cone,
                             QuadricForm::paraboloid, QuadricForm::hyperboloid, QuadricForm::general}) {
        const std::string name = form_name(form);
        CAPTURE(name);
        Pcg32 rng(2000 + uint64_t(form));
        int spawned = 0, rehits = 0;
        for (int inst = 0; inst < 4; ++inst) {
            Oracle o;
            const float scale = std::pow(10.0f, -2.0f + 5.0f * rng.next_float());
            const float offset = scale * std::pow(10.0f, 2.0f * rng.next_float() - 1.0f);
            const Quadric q = make_instance(form, rng, scale, offset, inst % 2 == 1, o);
            for (int i = 0; i < per_instance; ++i) {
                const Ray ray = random_ray(rng, q.bounds(), o);
                const QuadricHit h = q.intersect(ray);
                if (!h.hit()) continue;
                const QuadricSurface s = q.surface(ray, h);
                const VL p(s.p);
                // Where two parts meet (cap rims) or at the cone apex a short second hit is real geometry.
                if (o.capped && o.clip_margin(p) < 0.02L * scale) continue;
                if (form == QuadricForm::cone && dot(o.local(p) - o.origin, o.axis) < 0.05L * o.height)
                    continue;
                for (float side : {1.0f, -1.0f}) {
                    const Vec3 n = s.n * side;
                    const Vec3 dir =
                        Frame(n).to_world(sample_cosine_hemisphere({rng.next_float(), rng.next_float()}));
                    if (dot(dir, n) < 0.05f) continue;
                    const QuadricHit again = q.intersect(make_ray(offset_ray_origin(s.p, n), dir));
                    ++spawned;
                    if (again.hit() && again.t < 1e-3f * scale) {
                        if (++rehits <= 5)
                            MESSAGE("re-hit at t ", again.t, " scale ", scale, " side ", side, " part ",
                                    int(h.part));
                    }
                }
            }
        }
        CHECK(spawned > 4 * per_instance / 10);
        CHECK(rehits == 0);
    }
}

namespace {

/// Random point strictly inside the unit ball (rejection sampling).
Vec3 inside_unit_ball(Pcg32& rng) {
    for (;;) {
        const Vec3 v(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        if (length_squared(v) < 1.0f) return v;
    }
}

/// World point from pre-transform coordinates (the oracle's rigid user transform).
Vec3 to_world(const Oracle& o, const VL& local) { return Vec3(o.world_vector(local) + o.trans); }

}  // namespace

TEST_CASE("quadric: closed shapes have no holes (every ray from inside hits)") {
    const int per_instance = kSanitized ? 2000 : 20000;
    Pcg32 rng(3000);
    SUBCASE("ellipsoid") {
        int escapes = 0;
        for (int inst = 0; inst < 5; ++inst) {
            Oracle o;
            const float scale = std::pow(10.0f, -2.0f + 5.0f * rng.next_float());
            const Quadric q =
                make_instance(QuadricForm::ellipsoid, rng, scale, 100 * scale * rng.next_float(), false, o);
            for (int i = 0; i < per_instance; ++i) {
                const VL local = o.origin + VL(inside_unit_ball(rng) * 0.999f) * o.radii;
                const Ray ray = make_ray(to_world(o, local), random_unit(rng));
                escapes += !q.intersect(ray).hit();
            }
        }
        CHECK(escapes == 0);
    }
    SUBCASE("capped cylinder and cone, rays aimed at the rims") {
        int escapes = 0;
        for (QuadricForm form : {QuadricForm::cylinder, QuadricForm::cone}) {
            for (int inst = 0; inst < 4; ++inst) {
                Oracle o;
                const float scale = std::pow(10.0f, -2.0f + 5.0f * rng.next_float());
                const Quadric q = make_instance(form, rng, scale, 100 * scale * rng.next_float(), true, o);
                const Frame frame{Vec3(o.axis)};
                const LD r_top = form == QuadricForm::cone ? o.height * o.tan_angle : o.radius;
                for (int i = 0; i < per_instance; ++i) {
                    // Inside: a point on the axis, pushed sideways by less than the local radius.
                    const LD h = o.height * (0.02L + 0.96L * LD(rng.next_float()));
                    const LD r_here = form == QuadricForm::cone ? h * o.tan_angle : o.radius;
                    const Vec2 disk = sample_disk_concentric({rng.next_float(), rng.next_float()});
                    const VL inside =
                        o.origin + o.axis * h + VL(frame.to_world(Vec3(disk.x, disk.y, 0))) * (0.9L * r_here);
                    // Target: a point of the top (or, for cylinders, bottom) rim.
                    const float phi = 2 * kPi * rng.next_float();
                    const bool top = form == QuadricForm::cone || rng.next_float() < 0.5f;
                    const VL rim = o.origin + o.axis * (top ? o.height : LD(0)) +
                                   VL(frame.to_world(Vec3(std::cos(phi), std::sin(phi), 0))) * r_top;
                    const Vec3 org = to_world(o, inside);
                    const Ray ray = make_ray(org, to_world(o, rim) - org);
                    escapes += !q.intersect(ray).hit();
                }
            }
        }
        CHECK(escapes == 0);
    }
}

TEST_CASE("quadric: placing a canonical shape by world_from_object equals placing it by parameters") {
    // How a parsed QuadricDesc maps onto the factories: origin 0, axis +z, and
    // the desc's world_from_local as world_from_object.
    Pcg32 rng(4000);
    const Mat4 rot = Mat4::rotate_euler({30, -50, 110});
    const Vec3 base(1.5f, -2, 0.25f), axis = rot.apply_vector({0, 0, 1});
    const Mat4 frame = Mat4::translate(Vec3d(base)) * rot;
    const Quadric pairs[][2] = {
        {make_cylinder(base, axis, 0.7f, 1.3f, true),
         make_cylinder({0, 0, 0}, {0, 0, 1}, 0.7f, 1.3f, true, frame)},
        {make_cone(base, axis, 25, 1.1f, true), make_cone({0, 0, 0}, {0, 0, 1}, 25, 1.1f, true, frame)},
        {make_paraboloid(base, axis, 0.8f, 0.9f), make_paraboloid({0, 0, 0}, {0, 0, 1}, 0.8f, 0.9f, frame)},
        {make_hyperboloid(base, axis, 1, 0.4f, 2), make_hyperboloid({0, 0, 0}, {0, 0, 1}, 1, 0.4f, 2, frame)},
    };
    int mismatches = 0, hits = 0;
    for (const auto& pair : pairs) {
        for (int i = 0; i < 2000; ++i) {
            const Vec3 org = base + random_unit(rng) * 4.0f;
            const Vec3 target =
                base + Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * 2.0f;
            const Ray ray = make_ray(org, target - org);
            const QuadricHit a = pair[0].intersect(ray), b = pair[1].intersect(ray);
            hits += a.hit();
            mismatches +=
                a.hit() != b.hit() || (a.hit() && (std::abs(a.t - b.t) > 1e-5f || a.part != b.part));
        }
    }
    CHECK(hits > 1000);
    CHECK(mismatches == 0);
}
