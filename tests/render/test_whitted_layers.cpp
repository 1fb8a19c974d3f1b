// The whitted integrator and pbr's clearcoat and sheen: the coat a mirror of
// weight clearcoat x F, the sheen part of the diffuse term, the base scaled by
// what the layers let through, as the path tracer weighs them.
#include <doctest/doctest.h>

#include <cmath>

#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A pbr floor z = 0 (material 1) that reflects only through its layers unless they say
/// otherwise: no specular layer (KHR_materials_specular 0), base colour `base`.
SceneDesc floor_scene(Rgb base, Rgb background) {
    SceneDesc d = empty_scene(background);
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = base;
    m.metallic = 0.0f;
    m.roughness = 0.5f;
    m.specular = 0.0f;
    d.materials.push_back(m);
    d.planes.push_back({Vec3(0, 0, 0), Vec3(0, 0, 1), 1});
    return d;
}

MaterialDesc& floor_material(SceneDesc& d) { return d.materials[1]; }

Rgb whitted_radiance(const SceneDesc& d, const Ray& ray) {
    SceneDesc copy = d;
    copy.render.integrator = IntegratorType::whitted;
    const Scene scene = build_scene(copy);
    Sampler sampler(1, SamplerType::independent);
    sampler.start(0, 0, 0);
    return estimate_radiance(scene, ray, sampler, 4);
}

/// A ray onto the floor's origin at cos `cos` to its normal, and where its mirror image goes.
Ray onto_floor(float cos, Vec3* mirrored) {
    const float sin = std::sqrt(1.0f - cos * cos);
    *mirrored = Vec3(sin, 0.0f, cos);
    return {Vec3(-sin, 0.0f, cos) * 5.0f, Vec3(sin, 0.0f, -cos), 0.0f, kInfinity, 0.0f};
}

}  // namespace

TEST_CASE("whitted: a clearcoat mirrors a bright object at the weight clearcoat x F") {
    const Rgb le(40.0f, 20.0f, 10.0f);
    for (float cos : {0.9f, 0.2f}) {
        CAPTURE(cos);
        Vec3 mirrored;
        const Ray ray = onto_floor(cos, &mirrored);
        SceneDesc d = floor_scene(Rgb(0.0f), Rgb(0.0f));  // black base, black sky
        d.materials.push_back(emissive(le));              // a lamp where the mirror image points
        d.spheres.push_back({mirrored * 6.0f, 1.0f, uint32_t(d.materials.size() - 1), {}});
        CHECK(whitted_radiance(d, ray) == Rgb(0.0f));  // nothing to see without the coat
        for (float clearcoat : {1.0f, 0.5f}) {
            floor_material(d).layers.clearcoat = clearcoat;
            floor_material(d).layers.clearcoat_roughness = 0.3f;  // ignored: a preview's coat is a mirror
            const float f = clearcoat * (0.04f + 0.96f * std::pow(1.0f - cos, 5.0f));
            const Rgb seen = whitted_radiance(d, ray);
            for (int c = 0; c < 3; ++c) CHECK(seen[c] == doctest::Approx(le[c] * f).epsilon(1e-5));
        }
        // The mirror image is the lamp's: moved away from the mirror direction, it is gone.
        d.spheres.back().center = Vec3(-mirrored.x, 0.0f, mirrored.z) * 6.0f + Vec3(0, 4, 0);
        CHECK(whitted_radiance(d, ray) == Rgb(0.0f));
    }
}

TEST_CASE("whitted: under a uniform sky the layers reflect what the path tracer's do") {
    // A white base under a red sheen and a smooth coat, in a uniform sky of 1: the
    // path tracer's one bounce gives the directional albedo of the layered BSDF,
    // (1, 1 - E_sheen, 1 - E_sheen) up to the coat's tiny rough-reflection loss;
    // whitted's ambient and mirror terms must give the same.
    SceneDesc d = floor_scene(Rgb(1.0f), Rgb(1.0f));
    floor_material(d).layers.sheen_color = Rgb(1.0f, 0.0f, 0.0f);
    floor_material(d).layers.sheen_roughness = 0.5f;
    Vec3 unused;
    for (float clearcoat : {0.0f, 1.0f})
        for (float cos : {0.9f, 0.3f}) {
            CAPTURE(clearcoat);
            CAPTURE(cos);
            floor_material(d).layers.clearcoat = clearcoat;
            const Ray ray = onto_floor(cos, &unused);
            const Rgb whitted = whitted_radiance(d, ray);
            const Stat path = radiance_stats(build_scene(d), ray, scaled(20000), 4);
            CHECK(within(path, whitted, 4.0f, 2e-3f));
            CHECK(whitted.x == doctest::Approx(1.0f).epsilon(2e-3));
            CHECK(whitted.y < 0.99f);  // the sheen takes its share from the base
        }
}
