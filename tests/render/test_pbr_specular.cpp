// KHR_materials_specular in the pbr BSDF: F0 = min(F0(ior) x colour, 1) x strength,
// F90 = strength, and the base gets what the layer leaves.
#include <doctest/doctest.h>

#include <cmath>

#include "render/bsdf_pbr.h"
#include "render/ggx_albedo.h"
#include "bsdf_test_util.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc specular_pbr(Rgb base, float roughness, float strength, Rgb color) {
    MaterialDesc m = pbr(base, 0.0f, roughness);
    m.specular = strength;
    m.specular_color = color;
    return m;
}

Stat furnace(const MaterialDesc& m, float x) {
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials.push_back(m);
    d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
    const Scene scene = build_scene(d);
    return radiance_stats(scene, Ray{{x, -5, 0.1f}, {0, 1, 0}, 0.0f, kInfinity, 0.0f}, scaled(4000), 16);
}

}  // namespace

TEST_CASE("specular extension defaults leave the pbr BSDF as it was") {
    MaterialDesc m = specular_pbr(Rgb(0.5f), 0.4f, 1.0f, Rgb(1.0f));
    const Bsdf b = bsdf_of(m);
    CHECK(b.f0_color == Rgb(b.f0));
    CHECK(b.f90 == 1.0f);
    CHECK(b.f0 == doctest::Approx(0.04f));
}

TEST_CASE("specular colour above 1: F0 is clamped to 1 and a white furnace stays at or below 1") {
    const Bsdf b = bsdf_of(specular_pbr(Rgb(1.0f), 0.3f, 1.0f, Rgb(30.0f, 1.0f, 1.0f)));
    CHECK(b.f0_color.x == 1.0f);
    CHECK(b.f0_color.y == doctest::Approx(0.04f));
    CHECK(b.f0 == 1.0f);
    for (float roughness : {0.3f, 1.0f})
        for (float x : {0.0f, 0.8f}) {
            // A grey colour keeps every channel equal: exactly white.
            const Stat grey = furnace(specular_pbr(Rgb(1.0f), roughness, 1.0f, Rgb(3.0f)), x);
            INFO("roughness " << roughness << " x " << x << " grey " << grey.mean.x);
            CHECK(within(grey, Rgb(1.0f), 3, 0.01f));
            // A red-only colour: red reflects all, the other channels lose what red's layer takes.
            const Stat red = furnace(specular_pbr(Rgb(1.0f), roughness, 1.0f, Rgb(30.0f, 1.0f, 1.0f)), x);
            INFO("red " << red.mean.x << " " << red.mean.y);
            CHECK(red.mean.x == doctest::Approx(1.0f).epsilon(0.01 + 3 * double(red.se.x)));
            CHECK(red.mean.y <= 1.0f + 3 * red.se.y);
            CHECK(red.mean.y < red.mean.x);
        }
}

TEST_CASE("specularFactor 0 leaves a purely diffuse surface") {
    const Rgb base(0.6f, 0.3f, 0.2f);
    for (float roughness : {0.05f, 0.5f}) {
        const Bsdf b = bsdf_of(specular_pbr(base, roughness, 0.0f, Rgb(1.0f)));
        CHECK(b.f90 == 0.0f);
        for (float cos_o : {0.1f, 0.5f, 1.0f})
            for (float cos_i : {0.05f, 0.4f, 0.99f}) {
                const Vec3 wo = direction(cos_o, 0.3f);
                // wi includes the mirror direction, where a specular lobe would peak.
                for (const Vec3& wi : {direction(cos_i, 2.0f), Vec3(-wo.x, -wo.y, wo.z)}) {
                    float pdf = 0;
                    const Rgb f = eval_bsdf(b, wo, wi, &pdf);
                    const Rgb lambert = base * (wi.z * kInvPi);
                    CHECK(length(f - lambert) <= 1e-5f * length(lambert));
                    CHECK(pdf == doctest::Approx(wi.z * kInvPi).epsilon(1e-5));
                }
            }
        const PbrLobeWeights w = pbr_lobe_weights(b, direction(0.7f, 0.0f));
        CHECK(w.specular == 0.0f);
    }
}

TEST_CASE("furnace: specular strength scales the dielectric layer's reflection") {
    // Head-on the layer reflects Ed = w (F0 E + (1 - F0) Es) + (1 - E) F_ms(w F_avg), the base 0.5 of the
    // rest.
    const GgxAlbedoTable& table = GgxAlbedoTable::get();
    const float w = 0.5f, roughness = 0.3f;
    const GgxAlbedo e = table.at(1.0f, roughness), avg = table.average(roughness);
    const float f0 = 0.04f * w, f_avg = f0 + (w - f0) / 21;
    const float f_ms = f_avg * f_avg * avg.e / (1 - f_avg * (1 - avg.e));
    const float ed = f0 * e.e + (w - f0) * e.e_schlick + (1 - e.e) * f_ms;
    const float predicted = ed + 0.5f * (1 - ed);
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials.push_back(specular_pbr(Rgb(0.5f), roughness, w, Rgb(1.0f)));
    d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
    const Scene scene = build_scene(d);
    const Stat s = radiance_stats(scene, Ray{{0, -5, 0}, {0, 1, 0}, 0.0f, kInfinity, 0.0f}, scaled(4000), 16);
    INFO("predicted " << predicted << " mean " << s.mean.x);
    CHECK(within(s, Rgb(predicted), 4, 0.003f));
    // Lower than at full strength: the difference is the test's resolving power.
    CHECK(predicted < 0.5f + 0.5f * (0.04f * e.e + 0.96f * e.e_schlick) - 0.003f);
}
