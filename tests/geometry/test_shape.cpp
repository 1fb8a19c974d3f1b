// Every shape through the one contract (geometry/shape.h): the same checks,
// templated over the shapes, against a brute-force reference per shape.
#include <doctest/doctest.h>

#include <cmath>
#include <optional>

#include "geometry/box.h"
#include "geometry/plane.h"
#include "geometry/quadric.h"
#include "geometry/shape.h"
#include "geometry/sphere.h"
#include "geometry/triangle.h"
#include "math/rng.h"

using namespace sahara;

namespace {

Vec3 random_in_cube(Pcg32& rng, float half) {
    return Vec3((2 * rng.next_float() - 1) * half, (2 * rng.next_float() - 1) * half,
                (2 * rng.next_float() - 1) * half);
}

/// A reference hit in long double by a method independent of the shape's own
/// test: t (in units of |dir|), and for triangles the barycentrics.
struct Reference {
    long double t, u = 0, v = 0;
};

/// Per shape: a random instance near the origin and the brute-force reference.
template <class S>
struct ShapeCase;

template <>
struct ShapeCase<Sphere> {
    static Sphere make(Pcg32& rng) { return Sphere{random_in_cube(rng, 1), 0.3f + rng.next_float()}; }
    /// |o + t d - c|² = r², both roots, the textbook way in long double.
    static std::optional<Reference> reference(const Sphere& s, const Ray& ray) {
        using L = long double;
        const L fx = L(ray.origin.x) - s.center.x, fy = L(ray.origin.y) - s.center.y,
                fz = L(ray.origin.z) - s.center.z;
        const L a = L(ray.dir.x) * ray.dir.x + L(ray.dir.y) * ray.dir.y + L(ray.dir.z) * ray.dir.z;
        const L b = 2 * (fx * ray.dir.x + fy * ray.dir.y + fz * ray.dir.z);
        const L c = fx * fx + fy * fy + fz * fz - L(s.radius) * s.radius;
        const L disc = b * b - 4 * a * c;
        if (disc < 0) return std::nullopt;
        for (const L t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)})
            if (t > ray.tmin && t < ray.tmax) return Reference{t};
        return std::nullopt;
    }
};

template <>
struct ShapeCase<Box> {
    static Box make(Pcg32& rng) {
        const Vec3 a = random_in_cube(rng, 1), b = random_in_cube(rng, 1);
        return Box{Bounds3{min(a, b), max(a, b)}};
    }
    /// The nearest of the six faces, each a plane crossing tested against its rectangle.
    static std::optional<Reference> reference(const Box& box, const Ray& ray) {
        std::optional<Reference> best;
        for (int axis = 0; axis < 3; ++axis)
            for (const float plane : {box.box.lo[axis], box.box.hi[axis]}) {
                if (ray.dir[axis] == 0.0f) continue;
                const long double t = (static_cast<long double>(plane) - ray.origin[axis]) / ray.dir[axis];
                if (!(t > ray.tmin && t < ray.tmax) || (best && t >= best->t)) continue;
                bool inside = true;
                for (int k = 0; k < 3; ++k) {
                    if (k == axis) continue;
                    const long double x = ray.origin[k] + t * ray.dir[k];
                    inside &= x >= box.box.lo[k] && x <= box.box.hi[k];
                }
                if (inside) best = Reference{t};
            }
        return best;
    }
};

template <>
struct ShapeCase<Plane> {
    static Plane make(Pcg32& rng) {
        return Plane{random_in_cube(rng, 1), normalize(random_in_cube(rng, 1) + Vec3(0, 0, 0.1f))};
    }
    static std::optional<Reference> reference(const Plane& pl, const Ray& ray) {
        using L = long double;
        const L denom = L(pl.normal.x) * ray.dir.x + L(pl.normal.y) * ray.dir.y + L(pl.normal.z) * ray.dir.z;
        if (denom == 0) return std::nullopt;
        const L t =
            ((L(pl.point.x) - ray.origin.x) * pl.normal.x + (L(pl.point.y) - ray.origin.y) * pl.normal.y +
             (L(pl.point.z) - ray.origin.z) * pl.normal.z) /
            denom;
        if (!(t > ray.tmin && t < ray.tmax)) return std::nullopt;
        return Reference{t};
    }
};

template <>
struct ShapeCase<TriangleVerts> {
    static TriangleVerts make(Pcg32& rng) {
        return TriangleVerts::of(random_in_cube(rng, 1), random_in_cube(rng, 1), random_in_cube(rng, 1));
    }
    /// Moeller-Trumbore in long double: t and the barycentrics of vertices 1 and 2.
    static std::optional<Reference> reference(const TriangleVerts& tri, const Ray& ray) {
        using L = long double;
        L p[3][3], o[3], d[3];
        for (int k = 0; k < 3; ++k) {
            for (int i = 0; i < 3; ++i) p[i][k] = tri.p[i][k];
            o[k] = ray.origin[k], d[k] = ray.dir[k];
        }
        L e1[3], e2[3], s[3];
        for (int k = 0; k < 3; ++k)
            e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k], s[k] = o[k] - p[0][k];
        auto cross = [](const L* a, const L* b, L* out) {
            out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2],
            out[2] = a[0] * b[1] - a[1] * b[0];
        };
        auto dot = [](const L* a, const L* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
        L pv[3], qv[3];
        cross(d, e2, pv);
        const L det = dot(e1, pv);
        if (det == 0) return std::nullopt;
        cross(s, e1, qv);
        const L u = dot(s, pv) / det, v = dot(d, qv) / det, t = dot(e2, qv) / det;
        if (u < 0 || v < 0 || u + v > 1 || !(t > ray.tmin && t < ray.tmax)) return std::nullopt;
        return Reference{t, u, v};
    }
};

template <>
struct ShapeCase<Quadric> {
    /// A capped cylinder: a shape with parts (side and two caps).
    static Quadric make(Pcg32& rng) {
        return make_cylinder(random_in_cube(rng, 0.5f), normalize(random_in_cube(rng, 1) + Vec3(0, 0, 0.1f)),
                             0.3f + 0.5f * rng.next_float(), 0.5f + rng.next_float(), true);
    }
    /// Brute force over the three parts: the side's implicit equation and the two cap
    /// disks, each solved on its own in long double in the object frame.
    static std::optional<Reference> reference(const Quadric& q, const Ray& ray) {
        using L = long double;
        const auto& m = q.object_from_world.m;
        L o[3], d[3];
        for (int i = 0; i < 3; ++i) {
            o[i] =
                m[i][0] * L(ray.origin.x) + m[i][1] * L(ray.origin.y) + m[i][2] * L(ray.origin.z) + m[i][3];
            d[i] = m[i][0] * L(ray.dir.x) + m[i][1] * L(ray.dir.y) + m[i][2] * L(ray.dir.z);
        }
        std::optional<Reference> best;
        auto consider = [&](L t, uint32_t part) {
            if (t > ray.tmin && t < ray.tmax && (!best || t < best->t)) best = Reference{t, 0, L(part)};
        };
        const L a = d[0] * d[0] + d[1] * d[1], b = 2 * (o[0] * d[0] + o[1] * d[1]),
                c = o[0] * o[0] + o[1] * o[1] - 1;
        const L disc = b * b - 4 * a * c;
        if (a > 0 && disc >= 0)
            for (const L t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)}) {
                const L z = o[2] + t * d[2];
                if (z >= q.clip_lo.z && z <= q.clip_hi.z) consider(t, uint32_t(QuadricPart::side));
            }
        if (d[2] != 0)
            for (const bool top : {false, true}) {
                const L t = ((top ? q.clip_hi.z : q.clip_lo.z) - o[2]) / d[2];
                const L x = o[0] + t * d[0], y = o[1] + t * d[1];
                if (x * x + y * y <= 1)
                    consider(t, uint32_t(top ? QuadricPart::top_cap : QuadricPart::bottom_cap));
            }
        return best;
    }
};

/// Rays from a shell around the shapes towards points near the origin: most pass near
/// or through the shape; some start inside it.
Ray random_ray(Pcg32& rng) {
    const Vec3 origin = random_in_cube(rng, 3), target = random_in_cube(rng, 1);
    Ray ray{origin, (target - origin) * (0.5f + rng.next_float())};
    if (rng.next_float() < 0.2f) ray.tmin = 0.1f;
    if (rng.next_float() < 0.2f) ray.tmax = 0.2f + 2 * rng.next_float();
    return ray;
}

/// Agreement in t relative to the ray length to the hit.
bool close(long double a, float b) {
    return std::fabs(double(a) - double(b)) <= 1e-4 * (1 + std::fabs(double(a)));
}

}  // namespace

TEST_CASE_TEMPLATE("shape contract: intersect agrees with brute force and occluded with intersect", S, Sphere,
                   Box, Plane, TriangleVerts, Quadric) {
    static_assert(Shape<S>);
    Pcg32 rng(17);
    int hits = 0, misses = 0, disagree = 0, checked = 0, window_mismatch = 0;
    for (int shape = 0; shape < 200; ++shape) {
        const S s = ShapeCase<S>::make(rng);
        for (int i = 0; i < 100; ++i) {
            const Ray ray = random_ray(rng);
            const std::optional<ShapeHit> h = s.intersect(ray);
            REQUIRE(s.occluded(ray) == h.has_value());
            const std::optional<Reference> ref = ShapeCase<S>::reference(s, ray);
            ++checked;
            if (!h) {
                ++misses;
                // A graze or a hit within rounding of the interval's ends may go either way.
                if (ref && !(close(ref->t, ray.tmin) || close(ref->t, ray.tmax))) ++disagree;
                continue;
            }
            ++hits;
            REQUIRE(h->t > ray.tmin);
            REQUIRE(h->t < ray.tmax);
            if constexpr (S::kBounded) {
                const Bounds3 b = s.bounds();
                const Vec3 p = ray.at(h->t), slack(1e-4f * (1 + max_component(abs(p))));
                CHECK(Bounds3{b.lo - slack, b.hi + slack}.contains(p));
            }
            // Nearest: nothing in front of it (a sphere's t is its double root rounded, so
            // the interval ends a float step short). Consistent: the same hit in a narrow
            // window around it (a graze or a cap rim may put a second hit inside).
            Ray before = ray;
            before.tmax = std::nextafter(h->t, -kInfinity);
            CHECK_FALSE(s.intersect(before).has_value());
            Ray around = ray;
            const float eps = 1e-5f * (1 + std::fabs(h->t));
            around.tmin = h->t - eps, around.tmax = h->t + eps;
            const std::optional<ShapeHit> again = s.intersect(around);
            if (!again || again->t != h->t || again->part != h->part) ++window_mismatch;
            if (!ref || !close(ref->t, h->t)) {
                ++disagree;
                continue;
            }
            if constexpr (std::is_same_v<S, TriangleVerts>) {
                CHECK(std::fabs(double(ref->u) - double(h->u)) < 1e-3);
                CHECK(std::fabs(double(ref->v) - double(h->v)) < 1e-3);
            } else if constexpr (std::is_same_v<S, Quadric>) {
                // The reference stores the part in v; a hit on the rim may pick either.
                if (ref->v != h->part) ++disagree;
            } else {
                CHECK(h->u == 0.0f);
                CHECK(h->v == 0.0f);
                CHECK(h->part == 0u);
            }
        }
    }
    INFO("hits " << hits << ", misses " << misses << ", disagreements " << disagree << ", window mismatches "
                 << window_mismatch);
    CHECK(hits > checked / 20);
    CHECK(misses > checked / 10);
    CHECK(disagree <= checked / 1000);
    CHECK(window_mismatch <= checked / 1000);
}

TEST_CASE("shape contract: a plane is unbounded and says so") {
    static_assert(!Plane::kBounded);
    static_assert(Sphere::kBounded && Box::kBounded && TriangleVerts::kBounded && Quadric::kBounded);
    const Bounds3 b = Plane{{1, 2, 3}, {0, 0, 1}}.bounds();
    for (int k = 0; k < 3; ++k) {
        CHECK(b.lo[k] == -kInfinity);
        CHECK(b.hi[k] == kInfinity);
    }
    // It is hit from anywhere off it, however far along the plane.
    const Plane pl{{0, 0, 0}, {0, 1, 0}};
    const std::optional<ShapeHit> h = pl.intersect(Ray{{1e30f, 2, -1e30f}, {0, -1, 0}});
    REQUIRE(h.has_value());
    CHECK(h->t == 2.0f);
    CHECK_FALSE(pl.occluded(Ray{{0, 2, 0}, {1, 0, 0}}));  // parallel
}

TEST_CASE("shape contract: a shape's bounds contain it") {
    Pcg32 rng(5);
    const Sphere s{{1, 2, 3}, 0.5f};
    CHECK(s.bounds().lo.x == 0.5f);
    CHECK(s.bounds().hi.z == 3.5f);
    const TriangleVerts tri = TriangleVerts::of({0, 1, 2}, {-1, 5, 0}, {3, 0, 1});
    CHECK(tri.bounds().lo == Vec3(-1, 0, 0));
    CHECK(tri.bounds().hi == Vec3(3, 5, 2));
    const Box box{Bounds3{{0, 0, 0}, {1, 2, 3}}};
    CHECK(box.bounds().hi == Vec3(1, 2, 3));
    const Quadric q = ShapeCase<Quadric>::make(rng);
    CHECK_FALSE(q.bounds().empty());
}
