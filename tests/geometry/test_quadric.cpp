#include <doctest/doctest.h>

#include <cmath>
#include <optional>
#include <string>

#include "quadric_oracle.h"

using namespace sahara;
using namespace sahara::quadric_test;

TEST_CASE("quadric: hand-checked cases") {
    SUBCASE("cylinder: side from outside and inside, axis-parallel rays, caps") {
        const Quadric open = make_cylinder({0, 0, 0}, {0, 0, 3}, 1, 2, false);
        std::optional<ShapeHit> h = open.intersect(make_ray({-5, 0, 1}, {1, 0, 0}));
        CHECK(h->t == doctest::Approx(4.0f));
        CHECK(open.surface(make_ray({-5, 0, 1}, {1, 0, 0}), *h).front_face);
        h = open.intersect(make_ray({0, 0, 1}, {2, 0, 0}));
        CHECK(h->t == doctest::Approx(0.5f));
        const QuadricSurface s = open.surface(make_ray({0, 0, 1}, {2, 0, 0}), *h);
        CHECK_FALSE(s.front_face);
        CHECK(s.n.x == doctest::Approx(1.0f));
        CHECK(s.uv.y == doctest::Approx(0.5f));
        // a = 0 exactly: along the axis an open tube is missed, a capped one hit on the cap.
        CHECK_FALSE(open.intersect(make_ray({0, 0, -1}, {0, 0, 1})).has_value());
        const Quadric closed = make_cylinder({0, 0, 0}, {0, 0, 1}, 1, 2, true);
        h = closed.intersect(make_ray({0.5f, 0, -1}, {0, 0, 1}));
        CHECK(h->t == doctest::Approx(1.0f));
        CHECK(h->part == uint32_t(QuadricPart::bottom_cap));
        CHECK(closed.surface(make_ray({0.5f, 0, -1}, {0, 0, 1}), *h).n.z == doctest::Approx(-1.0f));
        h = closed.intersect(make_ray({0.5f, 0, 1}, {0, 0, 1}));
        CHECK(h->t == doctest::Approx(1.0f));
        CHECK(h->part == uint32_t(QuadricPart::top_cap));
    }
    SUBCASE("the first root is clipped away: the second one counts") {
        const Quadric open = make_cylinder({0, 0, 0}, {0, 0, 1}, 1, 2, false);
        // Enters the infinite cylinder at z = 3 (above the top), leaves at z = 1.
        const std::optional<ShapeHit> h = open.intersect(make_ray({-3, 0, 5}, {1, 0, -1}));
        CHECK(h->t == doctest::Approx(4.0f));
        CHECK_FALSE(open.surface(make_ray({-3, 0, 5}, {1, 0, -1}), *h).front_face);
    }
    SUBCASE("cone, paraboloid (linear case), hyperboloid, ellipsoid, general") {
        const Quadric cone = make_cone({0, 0, 0}, {0, 0, 1}, 45, 1, false);
        CHECK(cone.intersect(make_ray({-2, 0, 0.5f}, {1, 0, 0}))->t == doctest::Approx(1.5f));
        CHECK_FALSE(
            cone.intersect(make_ray({-2, 0, -0.5f}, {1, 0, 0})).has_value());  // the other nappe is clipped
        const Quadric para = make_paraboloid({0, 0, 0}, {0, 0, 1}, 1, 1);
        const std::optional<ShapeHit> hp = para.intersect(make_ray({0.5f, 0, 5}, {0, 0, -1}));
        CHECK(hp->t == doctest::Approx(4.75f));
        CHECK_FALSE(para.surface(make_ray({0.5f, 0, 5}, {0, 0, -1}), *hp).front_face);
        const Quadric hyp = make_hyperboloid({0, 0, 0}, {0, 0, 1}, 2, 1, 2);
        CHECK(hyp.intersect(make_ray({-5, 0, 0}, {1, 0, 0}))->t == doctest::Approx(4.0f));
        CHECK(hyp.intersect(make_ray({-5, 0, 0.5f}, {1, 0, 0}))->t == doctest::Approx(5.0 - std::sqrt(1.75)));
        const Quadric ell = make_ellipsoid({1, 2, 3}, {1, 2, 3});
        CHECK(ell.intersect(make_ray({1, 2, -10}, {0, 0, 1}))->t == doctest::Approx(10.0f));
        CHECK(ell.intersect(make_ray({1, -10, 3}, {0, 1, 0}))->t == doctest::Approx(10.0f));
        CHECK(ell.bounds().contains(Bounds3{{0, 0, 0}, {2, 4, 6}}));
        // Saddle z = x² - y² in [-1,1]³: straight down through (0.5, 0) lands at z = 0.25.
        const Quadric saddle =
            make_general_quadric({1, -1, 0, 0, 0, 0, 0, 0, -1, 0}, {{-1, -1, -1}, {1, 1, 1}});
        CHECK(saddle.intersect(make_ray({0.5f, 0, 3}, {0, 0, -1}))->t == doctest::Approx(2.75f));
        CHECK_FALSE(saddle.intersect(make_ray({3, 0, 3}, {0, 0, -1})).has_value());
    }
    SUBCASE("tmin and tmax bound the interval") {
        const Quadric ell = make_ellipsoid({0, 0, 0}, {1, 1, 1});
        CHECK_FALSE(ell.intersect(make_ray({0, 0, -5}, {0, 0, 1}, 0, 3.9f)).has_value());
        CHECK(ell.intersect(make_ray({0, 0, -5}, {0, 0, 1}, 4.5f))->t == doctest::Approx(6.0f));
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
            const std::optional<ShapeHit> a = pair[0].intersect(ray), b = pair[1].intersect(ray);
            hits += a.has_value();
            mismatches += a.has_value() != b.has_value() ||
                          (a && b && (std::abs(a->t - b->t) > 1e-5f || a->part != b->part));
        }
    }
    CHECK(hits > 1000);
    CHECK(mismatches == 0);
}

TEST_CASE("quadric: hit_at finds the part intersect() returned from t alone") {
    // Scene::interact gets t and the primitive id, not the part (geometry/hit.h).
    Pcg32 rng(4100);
    int caps = 0, sides = 0;
    for (QuadricForm form : {QuadricForm::cylinder, QuadricForm::cone}) {
        for (int inst = 0; inst < 4; ++inst) {
            Oracle o;
            const Quadric q = make_instance(form, rng, 1.0f, 10.0f * rng.next_float(), true, o);
            for (int i = 0; i < 5000; ++i) {
                const Ray ray = random_ray(rng, q.bounds(), o);
                const std::optional<ShapeHit> h = q.intersect(ray);
                if (!h) continue;
                Ray shortened = ray;  // as the integrator passes it: tmax lowered to the hit
                shortened.tmax = h->t;
                const ShapeHit again = q.hit_at(shortened, h->t);
                CHECK(again.t == h->t);
                CHECK(again.part == h->part);
                (h->part == uint32_t(QuadricPart::side) ? sides : caps) += 1;
            }
        }
    }
    CHECK(caps > 500);
    CHECK(sides > 500);
}
