// KHR_materials_dispersion: the ior per wavelength, the path's choice of one
// channel and wavelength, the material left bit for bit without it, and a
// slab that sends red and blue light to different places.
#include <doctest/doctest.h>

#include "pbr_test_util.h"
#include "render/dispersion.h"
#include "mesh_fixtures.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Clear glass (volume, nearly smooth) of ior 1.5 and the given dispersion.
MaterialDesc dispersive_glass(float dispersion) {
    MaterialDesc m = pbr(Rgb(1.0f), 0.0f, 0.0f);
    m.transmission = 1.0f;
    m.ior = 1.5f;
    m.dispersion = dispersion;
    return m;
}

Bsdf bsdf_at(const MaterialDesc& m, float wavelength_nm) {
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    return make_bsdf(m, si, {}, wavelength_nm);
}

/// A horizontal quad at height z over x in [x0, x1], y in [-8, 8], facing +z, material 2.
TriangleMesh floor_strip(float x0, float x1, float z) {
    TriangleMesh m;
    m.material = 2;
    m.positions = {{x0, -8, z}, {x1, -8, z}, {x1, 8, z}, {x0, 8, z}};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

}  // namespace

TEST_CASE("dispersion: the ior follows the Abbe number and is the material's at the d line") {
    // V = 20 / dispersion = (n_d - 1) / (n_F - n_C), F and C the 486.13 and 656.27 nm lines.
    for (float dispersion : {0.3f, 1.0f, 2.0f}) {
        const float abbe = 20.0f / dispersion;
        const float f = dispersed_ior(1.5f, dispersion, 486.13f),
                    c = dispersed_ior(1.5f, dispersion, 656.27f);
        CHECK((f - c) == doctest::Approx(0.5f / abbe).epsilon(1e-3));
        CHECK(dispersed_ior(1.5f, dispersion, 587.56f) == doctest::Approx(1.5f).epsilon(1e-5));
        CHECK(dispersed_ior(1.5f, dispersion, 420.0f) > dispersed_ior(1.5f, dispersion, 680.0f));
    }
    CHECK(dispersed_ior(1.7f, 0.0f, 450.0f) == 1.7f);
    CHECK(dispersed_ior(1.01f, 40.0f, 700.0f) >= 1.0f);  // never below vacuum
}

TEST_CASE("dispersion: a path picks each channel a third of the time and a wavelength in its band") {
    int count[3] = {0, 0, 0};
    for (int i = 0; i < 300; ++i) {
        const PathWavelength w = sample_path_wavelength((float(i) + 0.5f) / 300.0f);
        ++count[w.channel];
        const float lo = w.channel == 0 ? 600.0f : w.channel == 1 ? 500.0f : 400.0f;
        CHECK(w.nm >= lo);
        CHECK(w.nm <= lo + 100.0f);
        CHECK(w.weight()[w.channel] == 3.0f);
        CHECK(w.weight()[(w.channel + 1) % 3] == 0.0f);
    }
    for (int c : count) CHECK(c == 100);
    CHECK(sample_path_wavelength(0.999999f).channel == 2);
}

TEST_CASE("dispersion: without a wavelength or without dispersion the pbr BSDF is bit for bit the same") {
    const MaterialDesc plain = dispersive_glass(0.0f), dispersive = dispersive_glass(1.0f);
    const Bsdf a = bsdf_of(plain), b = bsdf_of(dispersive), c = bsdf_at(plain, 450.0f);
    for (const Bsdf* other : {&b, &c}) {
        CHECK(other->eta == a.eta);
        CHECK(other->f0 == a.f0);
    }
    // A thin wall does not disperse.
    MaterialDesc thin = dispersive;
    thin.thin_walled = true;
    CHECK(bsdf_at(thin, 450.0f).f0 == bsdf_of(thin).f0);
    // A volume does, reflection and refraction alike.
    const Bsdf blue = bsdf_at(dispersive, 450.0f), red = bsdf_at(dispersive, 650.0f);
    CHECK(blue.eta > a.eta + 0.01f);
    CHECK(red.eta < a.eta - 0.005f);
    CHECK(blue.f0 > red.f0);
}

TEST_CASE("dispersion: at every wavelength the glass conserves energy and samples its pdf") {
    const int n = scaled(20000);
    for (float roughness : {0.3f, 0.6f})
        for (float nm : {405.0f, 550.0f, 695.0f}) {
            MaterialDesc m = dispersive_glass(2.0f);
            m.roughness = roughness;
            const Bsdf b = bsdf_at(m, nm);
            for (float cos_o : {0.9f, 0.3f}) {
                const Vec3 wo = direction(cos_o, 0.7f);
                const Stat s = directional_albedo(b, wo, n);
                INFO("roughness " << roughness << " nm " << nm << " cos_o " << cos_o << " albedo "
                                  << s.mean.x);
                for (int c = 0; c < 3; ++c) CHECK(s.mean[c] <= 1.0f + 4.0f * s.se[c] + 0.005f);
                CHECK(pbr_chi2_deviate(scaled(100000), b, wo) < 3.5);
            }
        }
}

TEST_CASE("dispersion: a tilted glass slab sends red and blue to different places") {
    // Light seen 60 degrees off the normal through a slab 10 thick travels
    // 10 tan(theta_t) sideways inside it: 7.08 at ior 1.5, about 6.9 for blue
    // (400-500 nm) and 7.1 for red (600-700 nm) at dispersion 1 (Abbe number
    // 20). The slab shifts the ray without turning it; under it a glowing strip
    // starts half way between where red and blue land.
    const float thickness = 10.0f, tan60 = std::sqrt(3.0f);
    const Vec3 origin(-6.5f, 0.2f, thickness + 1.0f);
    const Vec3 dir = normalize(Vec3(tan60, 0.0f, -1.0f));
    const float strip_z = -0.5f;
    const auto land = [&](float ior) {
        return origin.x + tan60 * (1.0f - strip_z) + thickness * std::tan(std::asin(std::sin(kPi / 3) / ior));
    };
    // Blue's longest wavelength lands nearest red's shortest; the strip starts between them.
    const float blue_far = land(dispersed_ior(1.5f, 1.0f, 500.0f)),
                red_near = land(dispersed_ior(1.5f, 1.0f, 600.0f));
    const float strip_start = 0.5f * (blue_far + red_near);
    REQUIRE(red_near - blue_far > 0.08f);
    REQUIRE(land(1.5f) > strip_start + 0.03f);
    const auto render = [&](float dispersion) {
        SceneDesc d = empty_scene(Rgb(0.0f));
        d.materials.push_back(dispersive_glass(dispersion));
        d.materials.push_back(emissive(Rgb(1.0f)));
        d.meshes.push_back(make_slab(8.0f, thickness));
        d.meshes.push_back(floor_strip(strip_start, strip_start + 3.0f, strip_z));
        return radiance_stats(build_scene(d), Ray{origin, dir, 0.0f, kInfinity, 0.0f}, scaled(6000), 8);
    };
    const Stat plain = render(0.0f), split = render(1.0f);
    INFO("plain " << plain.mean.x << " " << plain.mean.y << " " << plain.mean.z << " dispersive "
                  << split.mean.x << " " << split.mean.y << " " << split.mean.z);
    // Without dispersion every channel lands on the strip, through two faces (0.96^2 at normal incidence,
    // less at 60 degrees).
    CHECK(min_component(plain.mean) > 0.7f);
    CHECK(max_component(plain.mean) - min_component(plain.mean) < 1e-5f);
    // With it, red still does, blue misses.
    CHECK(split.mean.x > 0.7f - 4 * split.se.x);
    CHECK(split.mean.z < 0.05f);
}

TEST_CASE("white furnace: a dispersive slab under a white sky stays white") {
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials.push_back(dispersive_glass(1.5f));
    d.meshes.push_back(make_slab(8.0f, 1.0f));
    const Scene scene = build_scene(d);
    for (const Vec3& dir : {Vec3(0, 0, -1), normalize(Vec3(1, 0.3f, -1))}) {
        const Stat s =
            radiance_stats(scene, Ray{{0.1f, 0.2f, 3.0f}, dir, 0.0f, kInfinity, 0.0f}, scaled(8000), 32);
        INFO("dir " << dir.x << " albedo " << s.mean.x << " " << s.mean.y << " " << s.mean.z);
        CHECK(within(s, Rgb(1.0f), 4, 0.01f));
    }
}
