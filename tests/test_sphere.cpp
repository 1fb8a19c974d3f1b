#include <doctest/doctest.h>

#include <cmath>

#include "geometry/sphere.h"
#include "math/rng.h"

using namespace sahara;

namespace {

Ray make_ray(Vec3 o, Vec3 d) { return Ray{o, d, 0.0f, kInfinity, 0.0f}; }

}  // namespace

TEST_CASE("sphere: the five workshop cases") {
    const Vec3 c(0, 0, 0);
    const float r = 1;
    SUBCASE("two hits in front: the nearer one") {
        CHECK(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 1}), c, r) == doctest::Approx(4.0));
    }
    SUBCASE("ray starts inside: the exit point") {
        CHECK(intersect_sphere(make_ray({0, 0, 0.5f}, {0, 0, 1}), c, r) == doctest::Approx(0.5));
    }
    SUBCASE("sphere behind the ray: no hit") {
        CHECK(intersect_sphere(make_ray({0, 0, 5}, {0, 0, 1}), c, r) < 0);
    }
    SUBCASE("tangent ray: touches at one point") {
        double t = intersect_sphere(make_ray({1, 0, -5}, {0, 0, 1}), c, r);
        CHECK(t == doctest::Approx(5.0).epsilon(1e-3));
    }
    SUBCASE("miss") { CHECK(intersect_sphere(make_ray({2, 0, -5}, {0, 0, 1}), c, r) < 0); }
    SUBCASE("unnormalised direction: t in units of |dir|") {
        CHECK(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 2}), c, r) == doctest::Approx(2.0));
    }
    SUBCASE("tmin and tmax bound the interval") {
        Ray ray = make_ray({0, 0, -5}, {0, 0, 1});
        ray.tmax = 3.9f;
        CHECK(intersect_sphere(ray, c, r) < 0);
        ray.tmax = kInfinity;
        ray.tmin = 4.5f;
        CHECK(intersect_sphere(ray, c, r) == doctest::Approx(6.0));
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
        const double t = intersect_sphere(make_ray(origin, dir), center, radius);
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
