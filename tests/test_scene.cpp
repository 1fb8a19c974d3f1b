#include <doctest/doctest.h>

#include "math/rng.h"
#include "scene/scene.h"
#include "scene/scene_parser.h"

using namespace sahara;

TEST_CASE("scene: quadrics sit in the BVH beside spheres and give the quadric's own hits") {
    const SceneDesc desc = parse_scene_file(std::string(SAHARA_SOURCE_DIR) + "/scenes/quadrics.json");
    REQUIRE(desc.quadrics.size() == 6);
    const Scene scene = build_scene(desc);
    REQUIRE(scene.quadrics.size() == 6);
    Pcg32 rng(3);
    int quadric_hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Ray ray;
        ray.origin = Vec3(12 * rng.next_float() - 6, -8, 3 * rng.next_float());
        ray.dir = normalize(Vec3(0.2f * (rng.next_float() - 0.5f), 1, 0.3f * (rng.next_float() - 0.5f)));
        Ray r = ray;
        Hit hit;
        const bool found = scene.intersect(r, hit);
        // Reference: the nearest hit over every quadric and the floor plane, tested directly.
        float best = kInfinity;
        uint32_t best_q = kNoPrim;
        for (uint32_t q = 0; q < scene.quadrics.size(); ++q) {
            const QuadricHit qh = scene.quadrics[q].intersect(ray);
            if (qh.hit() && qh.t < best) { best = qh.t; best_q = q; }
        }
        const float floor_t = ray.dir.z < 0 ? -ray.origin.z / ray.dir.z : kInfinity;
        if (best_q != kNoPrim && best < floor_t) {
            REQUIRE(found);
            CHECK(prim_kind(hit.prim) == PrimKind::quadric);
            CHECK(prim_index(hit.prim) == best_q);
            CHECK(hit.t == doctest::Approx(best).epsilon(1e-5));
            const SurfaceInteraction si = scene.interact(r, hit);
            CHECK(length(si.ng) == doctest::Approx(1.0f).epsilon(1e-4));
            CHECK(dot(si.ng, ray.dir) <= 0.0f);
            ++quadric_hits;
        }
    }
    CHECK(quadric_hits > 2000);
}
