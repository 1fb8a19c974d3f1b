#include <doctest/doctest.h>

#include <cmath>
#include <optional>

#include "geometry/sphere.h"
#include "math/rng.h"

using namespace sahara;

namespace {

Ray make_ray(Vec3 o, Vec3 d) { return Ray{o, d, 0.0f, kInfinity, 0.0f}; }

/// t of the sphere's hit (Sphere::intersect), or -1 for a miss.
double sphere_t(const Ray& ray, const Vec3& c, float r) {
    const std::optional<ShapeHit> h = Sphere{c, r}.intersect(ray);
    return h ? double(h->t) : -1.0;
}

}  // namespace

TEST_CASE("sphere: the five workshop cases") {
    const Vec3 c(0, 0, 0);
    const float r = 1;
    SUBCASE("two hits in front: the nearer one") {
        CHECK(sphere_t(make_ray({0, 0, -5}, {0, 0, 1}), c, r) == doctest::Approx(4.0));
    }
    SUBCASE("ray starts inside: the exit point") {
        CHECK(sphere_t(make_ray({0, 0, 0.5f}, {0, 0, 1}), c, r) == doctest::Approx(0.5));
    }
    SUBCASE("sphere behind the ray: no hit") { CHECK(sphere_t(make_ray({0, 0, 5}, {0, 0, 1}), c, r) < 0); }
    SUBCASE("tangent ray: touches at one point") {
        double t = sphere_t(make_ray({1, 0, -5}, {0, 0, 1}), c, r);
        CHECK(t == doctest::Approx(5.0).epsilon(1e-3));
    }
    SUBCASE("miss") { CHECK(sphere_t(make_ray({2, 0, -5}, {0, 0, 1}), c, r) < 0); }
    SUBCASE("unnormalised direction: t in units of |dir|") {
        CHECK(sphere_t(make_ray({0, 0, -5}, {0, 0, 2}), c, r) == doctest::Approx(2.0));
    }
    SUBCASE("tmin and tmax bound the interval") {
        Ray ray = make_ray({0, 0, -5}, {0, 0, 1});
        ray.tmax = 3.9f;
        CHECK(sphere_t(ray, c, r) < 0);
        ray.tmax = kInfinity;
        ray.tmin = 4.5f;
        CHECK(sphere_t(ray, c, r) == doctest::Approx(6.0));
    }
}

TEST_CASE("sphere: the 20-minutes ground (radius 1e6) is hit within 1e-4 of its surface") {
    // A sphere of radius 1e6 centred 1e6 below the origin; rays from height 1.
    const Vec3 center(0, -1e6f, 0);
    const float radius = 1e6f;
    Pcg32 rng(7);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        // Steep to grazing: from 90 degrees below the horizon down to ~0.37 degrees
        // (the horizon itself dips only ~0.08 degrees at height 1).
        const float elev = -std::exp(-5.5f * rng.next_float()) * 1.5707f;
        const float az = 6.2831853f * rng.next_float();
        const Vec3 dir(std::cos(elev) * std::cos(az), std::sin(elev), std::cos(elev) * std::sin(az));
        const Vec3 origin(100.0f * (rng.next_float() - 0.5f), 1.0f, 100.0f * (rng.next_float() - 0.5f));
        const double t = sphere_t(make_ray(origin, dir), center, radius);
        REQUIRE(t > 0);
        ++hits;
        using LD = long double;
        const LD px = LD(origin.x) + LD(t) * LD(dir.x), py = LD(origin.y) + LD(t) * LD(dir.y) - LD(center.y),
                 pz = LD(origin.z) + LD(t) * LD(dir.z);
        const LD dist = std::sqrt(px * px + py * py + pz * pz) - LD(radius);
        CHECK(std::fabs(double(dist)) < 1e-4);
    }
    CHECK(hits == 20000);
}

TEST_CASE("sphere: the float pre-test never rejects a ray whose line meets the sphere") {
    // Lines at distance r (1 + delta) from the centre, delta from -1e-3 to +1e-3
    // down to 1e-9, for radii 1e-3 .. 1e6, centres up to 1e4 from the origin and
    // ray origins up to 1e3 radii away: a line inside the sphere (in long double)
    // must never be rejected; lines well outside must be (the test pays off).
    Pcg32 rng(11);
    int inside = 0, outside_rejected = 0, outside = 0;
    for (int i = 0; i < 200000; ++i) {
        const float r = std::pow(10.0f, -3.0f + 9.0f * rng.next_float());
        const Vec3 c(1e4f * (rng.next_float() - 0.5f), 1e4f * (rng.next_float() - 0.5f),
                     1e4f * (rng.next_float() - 0.5f));
        const Vec3 axis =
            normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
        const Vec3 side = normalize(cross(axis, std::fabs(axis.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
        const float mag = std::pow(10.0f, -9.0f + 6.0f * rng.next_float());
        const float delta = (rng.next_float() < 0.5f ? -mag : mag) * (i % 10 == 0 ? 1e3f : 1.0f);
        const float back = r * std::pow(10.0f, 3.0f * rng.next_float());
        const Vec3 origin = c + side * (r * (1.0f + delta)) - axis * back;
        const Vec3 dir = axis * std::pow(10.0f, -2.0f + 4.0f * rng.next_float());
        // The line's distance from the centre with the float inputs as given, in long double.
        using LD = long double;
        const LD fx = LD(origin.x) - c.x, fy = LD(origin.y) - c.y, fz = LD(origin.z) - c.z;
        const LD dd = LD(dir.x) * dir.x + LD(dir.y) * dir.y + LD(dir.z) * dir.z;
        const LD b = (fx * dir.x + fy * dir.y + fz * dir.z) / dd;
        const LD px = fx - b * dir.x, py = fy - b * dir.y, pz = fz - b * dir.z;
        const LD dist = std::sqrt(px * px + py * py + pz * pz);
        const bool rejected = sphere_clearly_missed(make_ray(origin, dir), c, r);
        if (dist <= LD(r)) {
            ++inside;
            if (rejected)
                FAIL_CHECK("rejected a line inside the sphere: r " << r << " dist/r " << double(dist / r));
        } else if (dist > 1.5L * r && std::fabs(c.x) + std::fabs(c.y) + std::fabs(c.z) < 1e3f * r) {
            ++outside;
            outside_rejected += rejected;
        }
    }
    CHECK(inside > 50000);
    CHECK(outside > 100);
    CHECK(outside_rejected == outside);
}
