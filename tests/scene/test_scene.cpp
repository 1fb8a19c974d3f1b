#include <doctest/doctest.h>

#include "math/rng.h"
#include "render/camera.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

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
            const std::optional<ShapeHit> qh = scene.quadrics[q].intersect(ray);
            if (qh && qh->t < best) {
                best = qh->t;
                best_q = q;
            }
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

#include "render/bvh_cost.h"

TEST_CASE("bvh-cost: the heat map shows more work where there is geometry, and a legend") {
    // A 10 x 10 wall of small spheres filling the lower half of the view.
    SceneDesc d = default_scene();
    d.spheres.clear();
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
            d.spheres.push_back({{float(i) - 4.5f, 10, float(j) - 9.0f}, 0.45f, 1, {0, 0, 0}});
    const Scene scene = build_scene(d);
    const BvhCostImage img = render_bvh_cost(scene, 64, 48, 1);
    CHECK(img.width == 64);
    CHECK(img.height > 48);  // legend strip below the picture
    CHECK(img.max_cost > 0);
    // The sphere in the centre costs more than the empty sky at the top.
    const Camera cam(scene.camera, 64, 48);
    const double centre = bvh_ray_cost(scene, cam.generate_ray(32.5f, 40.5f, {0.5f, 0.5f}, 0));
    const double sky = bvh_ray_cost(scene, cam.generate_ray(32.5f, 0.5f, {0.5f, 0.5f}, 0));
    CHECK(centre > sky);
    CHECK(heat_color(0.0f).z > heat_color(0.0f).x);  // cold is blue
    CHECK(heat_color(1.0f).x > heat_color(1.0f).z);  // hot is red
}

#include <filesystem>

#include "render/renderer.h"

TEST_CASE("every shipped scene parses and renders at 1 spp without NaN or Inf samples") {
    int scenes = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(SAHARA_SOURCE_DIR) + "/scenes")) {
        if (entry.path().extension() != ".json") continue;
        CAPTURE(entry.path().string());
        SceneDesc d = parse_scene_file(entry.path());
        d.render.width = 64;
        d.render.height = 48;
        d.render.spp = 1;
        const Scene scene = build_scene(d);
        Film film(64, 48);
        RenderOptions options;
        options.threads = 2;
        const RenderResult r = render_image(scene, film, options);
        CHECK(r.spp_done == 1);
        CHECK(film.nonfinite_samples() == 0);
        ++scenes;
    }
    CHECK(scenes >= 6);
}
