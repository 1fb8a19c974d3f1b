#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "quadric_oracle.h"

using namespace sahara;
using namespace sahara::quadric_test;

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
                const std::optional<ShapeHit> h = q.intersect(ray);
                if (!h) continue;
                const QuadricSurface s = q.surface(ray, *h);
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
                    const std::optional<ShapeHit> again =
                        q.intersect(make_ray(offset_ray_origin(s.p, n), dir));
                    ++spawned;
                    if (again && again->t < 1e-3f * scale) {
                        if (++rehits <= 5)
                            MESSAGE("re-hit at t ", again->t, " scale ", scale, " side ", side, " part ",
                                    int(h->part));
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
                escapes += !q.intersect(ray).has_value();
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
                    escapes += !q.intersect(ray).has_value();
                }
            }
        }
        CHECK(escapes == 0);
    }
}
