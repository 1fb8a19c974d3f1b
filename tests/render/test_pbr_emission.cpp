// Glowing pbr surfaces (glTF emissiveFactor) are area lights: light sampling
// picks them as it picks emissive materials, and MIS weighs what BSDF sampling finds.
#include <doctest/doctest.h>

#include <cmath>

#include "render/lights.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A Lambertian floor z = 0 (material 1) under a black sky, lit only by a small
/// quad at height 1 facing down with material `lamp` (material 2).
SceneDesc panel_scene(const MaterialDesc& lamp) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(lambertian(Rgb(0.5f)));
    d.materials.push_back(lamp);
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    TriangleMesh m;
    // Counter-clockwise seen from below: the front faces the floor.
    m.positions = {{-0.15f, -0.15f, 1}, {0.15f, 0.15f, 1}, {0.15f, -0.15f, 1}, {-0.15f, 0.15f, 1}};
    m.indices = {0, 1, 2, 0, 3, 1};
    m.material = 2;
    d.meshes.push_back(m);
    return d;
}

/// A pbr material that reflects nothing (black base, ior 1: no specular layer) and glows.
MaterialDesc glowing_pbr(Rgb radiance) {
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = Rgb(0.0f);
    m.metallic = 0;
    m.roughness = 0.5f;
    m.ior = 1.0f;
    m.radiance.color = radiance;
    return m;
}

/// KHR_materials_clearcoat's attenuation of the emission, written out: 1 - c (0.04 + 0.96 (1 - cos)^5).
float through_coat(float clearcoat, float cos) {
    return 1.0f - clearcoat * (0.04f + 0.96f * std::pow(1.0f - cos, 5.0f));
}

/// A camera ray from below onto the lamp's centre at cos `cos` to its normal.
Ray onto_lamp(float cos) {
    const Vec3 dir(std::sqrt(1.0f - cos * cos), 0.0f, cos);
    return {Vec3(0, 0, 1) - dir * 0.6f, dir, 0.0f, kInfinity, 0.0f};
}

}  // namespace

TEST_CASE("pbr emission: a clearcoat darkens the emission under it by its Fresnel and a sheen does not") {
    const Rgb le(20.0f, 10.0f, 5.0f);
    for (float cos : {1.0f, 0.1f}) {  // head-on and grazing
        CAPTURE(cos);
        const Ray ray = onto_lamp(cos);
        for (IntegratorType integrator : {IntegratorType::path, IntegratorType::whitted}) {
            CAPTURE(int(integrator));
            MaterialDesc lamp = glowing_pbr(le);
            CHECK(radiance_along(panel_scene(lamp), integrator, ray, 1) == le);
            lamp.layers.clearcoat = 0.8f;
            const Rgb coated = radiance_along(panel_scene(lamp), integrator, ray, 1);
            for (int c = 0; c < 3; ++c)
                CHECK(coated[c] == doctest::Approx(le[c] * through_coat(0.8f, cos)).epsilon(1e-5));
            lamp.layers.clearcoat = 0.0f;
            lamp.layers.clearcoat_roughness = 0.7f;  // a coat of weight 0 is no coat, whatever its roughness
            CHECK(radiance_along(panel_scene(lamp), integrator, ray, 1) == le);
            lamp.layers.sheen_color = Rgb(1.0f);  // KHR_materials_sheen leaves emission alone
            lamp.layers.sheen_roughness = 0.5f;
            CHECK(radiance_along(panel_scene(lamp), integrator, ray, 1) == le);
        }
    }
    CHECK(through_coat(0.8f, 0.1f) < 0.52f);  // the grazing view is the one that shows the coat
}

TEST_CASE("pbr emission: light sampling gets from a coated lamp the radiance a camera ray sees") {
    MaterialDesc lamp = glowing_pbr(Rgb(20.0f, 10.0f, 5.0f));
    lamp.layers.clearcoat = 1.0f;
    const Scene scene = build_scene(panel_scene(lamp));
    Sampler sampler(5, SamplerType::independent);
    sampler.start(0, 0, 0);
    int lamp_samples = 0;
    // Points on the floor from under the lamp to far beside it (grazing views of the lamp).
    for (float x : {0.0f, 0.5f, 2.0f, 6.0f}) {
        const Vec3 p(x, 0.3f, 0.0f);
        for (int i = 0; i < 64; ++i) {
            LightSample ls;
            if (!sample_light(scene, p, 0.0f, sampler.next_1d(), sampler.next_2d(), ls)) continue;
            ++lamp_samples;
            const float cos = std::abs(ls.wi.z);  // the lamp's normal is -z
            CHECK(ls.li.x == doctest::Approx(20.0f * through_coat(1.0f, cos)).epsilon(1e-5));
            // The camera ray along the sample's direction sees the same.
            Sampler unused(3, SamplerType::independent);
            unused.start(0, 0, 0);
            const Rgb camera = estimate_radiance(scene, Ray{p, ls.wi, 1e-4f, kInfinity, 0.0f}, unused, 1);
            CHECK(camera.x == doctest::Approx(ls.li.x).epsilon(1e-4));
        }
    }
    CHECK(lamp_samples > 100);
}

TEST_CASE("pbr emission: a glowing pbr quad lights the scene like an emissive quad of equal radiance") {
    const Scene pbr = build_scene(panel_scene(glowing_pbr(Rgb(20.0f, 10.0f, 5.0f))));
    const Scene emissive_lamp = build_scene(panel_scene(emissive(Rgb(20.0f, 10.0f, 5.0f))));
    // Both quads are sampled lights.
    CHECK(pbr.emitters.size() == 2);
    CHECK(emissive_lamp.emitters.size() == 2);
    const Ray ray{{1.0f, -1.0f, 0.8f}, normalize(Vec3(-0.8f, 0.9f, -0.8f)), 0.0f, kInfinity, 0.0f};
    const int n = scaled(6000);
    const Stat a = radiance_stats(pbr, ray, n, 4, 3);
    const Stat b = radiance_stats(emissive_lamp, ray, n, 4, 5);
    CHECK(agree(a, b, 4));
    CHECK(a.mean.x > 0.2f);
    // Light sampling, not BSDF sampling alone: the noise is the emissive quad's, no fireflies.
    CHECK(a.se.x < 1.5f * b.se.x);
    // The lamp seen directly (no MIS: a camera ray) has its radiance.
    const Ray up{{0, 0, 0.5f}, {0, 0, 1}, 0.0f, kInfinity, 0.0f};
    CHECK(within(radiance_stats(pbr, up, 16, 1), Rgb(20.0f, 10.0f, 5.0f), 1, 1e-4f));
}
