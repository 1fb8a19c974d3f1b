// Clearcoat and sheen over the pbr material (render/bsdf_layers.h): energy,
// sampling against the reported density, and the base left untouched when
// the layers are off.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "pbr_test_util.h"
#include "render/bsdf_layers.h"
#include "render/bsdf_pbr.h"
#include "render/ggx_albedo.h"
#include "render/sheen.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc coated(MaterialDesc m, float clearcoat, float coat_roughness) {
    m.layers.clearcoat = clearcoat;
    m.layers.clearcoat_roughness = coat_roughness;
    return m;
}

MaterialDesc sheened(MaterialDesc m, Rgb sheen, float sheen_roughness) {
    m.layers.sheen_color = sheen;
    m.layers.sheen_roughness = sheen_roughness;
    return m;
}

/// The BSDF of `m` with the coat's normal tilted away from the base's by `tilt` (radians).
Bsdf tilted_coat(const MaterialDesc& m, float tilt) {
    Bsdf b = bsdf_of(m);
    b.layers.coat_normal = Vec3(std::sin(tilt), 0.0f, std::cos(tilt));
    b.layers.coat_frame = true;
    return b;
}

/// The layered materials the tests run over: coats and sheens of every
/// roughness over dielectric, metallic and transmissive bases.
std::vector<MaterialDesc> layered_materials(Rgb base) {
    std::vector<MaterialDesc> out;
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.05f, 0.5f, 1.0f}) {
            const MaterialDesc m = pbr(base, metallic, roughness);
            for (float cr : {0.0f, 0.3f, 1.0f}) out.push_back(coated(m, 1.0f, cr));
            out.push_back(coated(m, 0.5f, 0.2f));
            for (float sr : {0.0f, 0.5f, 1.0f}) out.push_back(sheened(m, Rgb(1.0f), sr));
            out.push_back(coated(sheened(m, Rgb(0.9f, 0.5f, 0.1f), 0.4f), 0.7f, 0.1f));
        }
    MaterialDesc glass = coated(pbr(base, 0.0f, 0.3f), 1.0f, 0.1f);
    glass.transmission = 1.0f;
    out.push_back(glass);
    return out;
}

}  // namespace

TEST_CASE("clearcoat 0 and sheen colour 0 leave the pbr BSDF exactly as it is") {
    for (const MaterialDesc& base : {pbr(Rgb(0.8f, 0.3f, 0.1f), 0.0f, 0.4f), pbr(Rgb(0.9f), 1.0f, 0.2f)}) {
        // Roughnesses alone switch nothing on.
        MaterialDesc m = sheened(coated(base, 0.0f, 0.7f), Rgb(0.0f), 0.6f);
        CHECK_FALSE(bsdf_of(m).layers.on);
        // The layered path itself, forced on with zero layers, is the base bit for bit.
        Bsdf forced = bsdf_of(m);
        forced.layers.on = true;
        const Bsdf plain = bsdf_of(base);
        Sampler s(9, SamplerType::independent);
        s.start(0, 0, 0);
        for (int k = 0; k < 200; ++k) {
            const Vec3 wo = direction(0.05f + 0.9f * s.next_1d(), 6.0f * s.next_1d());
            const Vec3 wi = direction(2.0f * s.next_1d() - 1.0f, 6.0f * s.next_1d());
            float p_plain = 0, p_forced = 0;
            const Rgb f_plain = eval_pbr(plain, wo, wi, &p_plain),
                      f_forced = eval_pbr(forced, wo, wi, &p_forced);
            CHECK(f_plain == f_forced);
            CHECK(p_plain == p_forced);
            const Vec2 u = s.next_2d();
            const float u_lobe = s.next_1d();
            BsdfSample a, b;
            const bool ok_a = sample_pbr(plain, wo, u, u_lobe, a),
                       ok_b = sample_pbr(forced, wo, u, u_lobe, b);
            REQUIRE(ok_a == ok_b);
            if (ok_a) {
                CHECK(a.wi == b.wi);
                CHECK(a.weight == b.weight);
            }
        }
    }
}

TEST_CASE("pbr layers: no energy gain at any angle and roughness and factor") {
    const int n = scaled(20000);
    for (const MaterialDesc& m : layered_materials(Rgb(1.0f))) {
        const Bsdf b = bsdf_of(m);
        REQUIRE(b.layers.on);
        for (float cos_o : {1.0f, 0.7f, 0.3f, 0.1f, 0.02f}) {
            const Stat a = directional_albedo(b, direction(cos_o, 0.4f), n);
            INFO("metallic " << m.metallic << " roughness " << m.roughness << " clearcoat "
                             << m.layers.clearcoat << " coat roughness " << m.layers.clearcoat_roughness
                             << " sheen " << m.layers.sheen_color.x << " sheen roughness "
                             << m.layers.sheen_roughness << " transmission " << m.transmission << " cos_o "
                             << cos_o << " albedo " << a.mean.x << " se " << a.se.x);
            for (int c = 0; c < 3; ++c) CHECK(a.mean[c] <= 1.0f + 4.0f * a.se[c] + 0.01f);
        }
    }
}

TEST_CASE("pbr layers: a white base under a coat or a white sheen still reflects everything") {
    const int n = scaled(40000);
    for (float roughness : {0.1f, 0.6f})
        for (float metallic : {0.0f, 1.0f}) {
            const MaterialDesc m = pbr(Rgb(1.0f), metallic, roughness);
            for (const MaterialDesc& layered : {coated(m, 1.0f, 0.0f), coated(m, 1.0f, 0.8f),
                                                sheened(m, Rgb(1.0f), 0.3f), sheened(m, Rgb(1.0f), 1.0f)})
                for (float cos_o : {0.9f, 0.4f}) {
                    const Stat a = directional_albedo(bsdf_of(layered), direction(cos_o, 1.0f), n);
                    INFO("metallic " << metallic << " roughness " << roughness << " clearcoat "
                                     << layered.layers.clearcoat << " coat roughness "
                                     << layered.layers.clearcoat_roughness << " sheen roughness "
                                     << layered.layers.sheen_roughness << " cos_o " << cos_o << " albedo "
                                     << a.mean.x << " se " << a.se.x);
                    CHECK(within(a, Rgb(1.0f), 4, 0.02f));
                }
        }
}

TEST_CASE("pbr layers: the sampler follows the pdf eval_pbr reports (chi-square)") {
    const int n = scaled(200000);
    struct Case {
        Bsdf b;
        float cos_o;
        const char* what;
    };
    const MaterialDesc red = pbr(Rgb(0.8f, 0.1f, 0.1f), 0.0f, 0.5f);
    MaterialDesc glass = coated(pbr(Rgb(0.9f), 0.0f, 0.4f), 1.0f, 0.2f);
    glass.transmission = 1.0f;
    const Case cases[] = {
        {bsdf_of(coated(red, 1.0f, 0.1f)), 0.8f, "smooth coat over red"},
        {bsdf_of(coated(red, 1.0f, 0.2f)), 0.25f, "smooth coat over red, grazing"},
        {bsdf_of(coated(pbr(Rgb(0.9f, 0.6f, 0.2f), 1.0f, 0.6f), 0.6f, 0.5f)), 0.5f, "rough coat over metal"},
        {bsdf_of(sheened(red, Rgb(0.9f), 0.3f)), 0.6f, "sheen over red"},
        {bsdf_of(sheened(pbr(Rgb(0.2f), 0.0f, 0.9f), Rgb(1.0f), 1.0f)), 0.2f, "rough sheen, grazing"},
        {bsdf_of(coated(sheened(red, Rgb(0.5f, 0.8f, 0.9f), 0.5f), 0.8f, 0.3f)), 0.7f, "coat over sheen"},
        {tilted_coat(coated(red, 1.0f, 0.2f), 0.3f), 0.6f, "coat with its own normal"},
        {bsdf_of(glass), 0.7f, "coat over glass"}};
    for (const Case& c : cases) {
        const Vec3 wo = direction(c.cos_o, 1.0f);
        const double z = pbr_chi2_deviate(n, c.b, wo);
        INFO(std::string(c.what) << ": deviate " << z);
        CHECK(z < 3.5);
    }
}

TEST_CASE("pbr layers: pdfs integrate to the sampler's success rate and samples carry f / pdf") {
    const MaterialDesc red = pbr(Rgb(0.7f, 0.2f, 0.2f), 0.3f, 0.5f);
    for (const Bsdf& b : {bsdf_of(coated(red, 1.0f, 0.4f)), bsdf_of(sheened(red, Rgb(0.8f), 0.6f)),
                          bsdf_of(coated(sheened(red, Rgb(0.8f), 0.2f), 0.6f, 0.6f))}) {
        const Vec3 wo = direction(0.6f, 0.0f);
        const double integral = pbr_pdf_integral(b, wo);
        Sampler s(3, SamplerType::independent);
        s.start(0, 0, 0);
        int ok = 0;
        const int n = 100000;
        for (int k = 0; k < n; ++k) {
            BsdfSample bs;
            const Vec2 u = s.next_2d();
            if (!sample_pbr(b, wo, u, s.next_1d(), bs)) continue;
            ++ok;
            if (k % 97 != 0) continue;
            float p = 0;
            const Rgb f = eval_pbr(b, wo, bs.wi, &p);
            CHECK(bs.pdf == doctest::Approx(p).epsilon(1e-5));
            for (int c = 0; c < 3; ++c) CHECK(bs.weight[c] * p == doctest::Approx(f[c]).epsilon(1e-4));
        }
        INFO("clearcoat " << b.layers.clearcoat << " sheen " << b.layers.sheen.x);
        CHECK(integral == doctest::Approx(double(ok) / n).epsilon(0.01));
    }
}

TEST_CASE("pbr layers: a coat and a sheen add what their albedos say to the base") {
    // albedo(layered) = coat + (1 - coat) (sheen colour E_sheen + (1 - max(sheen) E_sheen) albedo(base)),
    // with coat = c F(mu) E_ggx(mu): each term checked against an estimate of the base alone.
    const int n = scaled(60000);
    const MaterialDesc base = pbr(Rgb(0.3f, 0.5f, 0.7f), 0.0f, 0.6f);
    for (float cos_o : {0.9f, 0.35f}) {
        const Vec3 wo = direction(cos_o, 0.5f);
        const Stat a_base = directional_albedo(bsdf_of(base), wo, n);
        const float fresnel = 0.04f + 0.96f * std::pow(1.0f - cos_o, 5.0f);
        const float coat = 0.8f * fresnel * GgxAlbedoTable::get().at(cos_o, 0.25f).e;
        const Rgb sheen(0.9f, 0.4f, 0.1f);
        const float e = SheenAlbedoTable::get().at(cos_o, 0.5f);
        const Rgb predicted = Rgb(coat) + (sheen * e + a_base.mean * (1.0f - 0.9f * e)) * (1.0f - coat);
        const Stat a = directional_albedo(bsdf_of(coated(sheened(base, sheen, 0.5f), 0.8f, 0.25f)), wo, n);
        INFO("cos_o " << cos_o << " predicted " << predicted.x << " " << predicted.y << " " << predicted.z
                      << " got " << a.mean.x << " " << a.mean.y << " " << a.mean.z);
        CHECK(coat > 0.02f);
        CHECK(e > 0.02f);
        CHECK(within(a, predicted, 4, 0.01f));
    }
}

TEST_CASE("sheen albedo table: converged and equal to a Monte Carlo estimate of the lobe") {
    const SheenAlbedoTable& t = SheenAlbedoTable::get();
    const SheenAlbedoTable fine(128);
    for (float mu : {0.1f, 0.5f, 1.0f})
        for (float r : {0.2f, 0.6f, 1.0f}) {
            CHECK(fine.at(mu, r) == doctest::Approx(t.at(mu, r)).epsilon(5e-3));
            const float alpha = sheen_alpha(r);
            const Vec3 wo = direction(mu, 0.0f);
            const Stat s = sample_stats(scaled(200000), 4, [&](Sampler& sampler) {
                const Vec2 u = sampler.next_2d();
                const float z = u.x, rr = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2 * kPi * u.y;
                return Rgb(2 * kPi * sheen_lobe(wo, Vec3(rr * std::cos(phi), rr * std::sin(phi), z), alpha));
            });
            INFO("mu " << mu << " roughness " << r << " table " << t.at(mu, r) << " estimate " << s.mean.x);
            CHECK(std::abs(s.mean.x - t.at(mu, r)) <= 4 * s.se.x + 0.01f * t.at(mu, r) + 1e-4f);
        }
    CHECK(t.at(0.5f, 1.0f) > t.at(1.0f, 1.0f));  // sheen grows towards grazing views
}

TEST_CASE("white furnace: a white pbr sphere under a clearcoat or a white sheen stays white") {
    for (float roughness : {0.2f, 0.8f}) {
        const MaterialDesc base = pbr(Rgb(1.0f), 0.0f, roughness);
        for (const MaterialDesc& m :
             {coated(base, 1.0f, 0.1f), coated(base, 1.0f, 0.9f), sheened(base, Rgb(1.0f), 0.5f)}) {
            SceneDesc d = empty_scene(Rgb(1.0f));
            d.materials.push_back(m);
            d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
            const Scene scene = build_scene(d);
            for (float x : {0.0f, 0.8f}) {
                const Stat s = radiance_stats(scene, Ray{{x, -5, 0.1f}, {0, 1, 0}, 0.0f, kInfinity, 0.0f},
                                              scaled(4000), 16);
                INFO("roughness " << roughness << " clearcoat " << m.layers.clearcoat << " x " << x
                                  << " mean " << s.mean.x << " se " << s.se.x);
                CHECK(within(s, Rgb(1.0f), 3, 0.01f));
            }
        }
    }
}

TEST_CASE("pbr layers read their textures: clearcoat R and coat roughness G and sheen RGB and roughness A") {
    auto img = std::make_shared<Image>();
    img->width = img->height = 1;
    img->rgba = {0.5f, 0.25f, 0.75f, 0.4f};
    TextureDesc t;
    t.image = img;
    auto tilt = std::make_shared<Image>(*img);
    tilt->rgba = {0.8f, 0.5f, 0.8f, 1.0f};  // a normal leaning towards +x
    TextureDesc tilted;
    tilted.image = tilt;
    const std::vector<TextureDesc> textures{t, tilted};
    MaterialDesc m = pbr(Rgb(0.5f), 0.0f, 0.5f);
    m.layers = {0.8f, 0, 0.6f, 0, -1, 1.0f, Rgb(1.0f, 0.5f, 1.0f), 0, 0.5f, 0};
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    si.uv = {0.5f, 0.5f};
    si.tangent = Vec3(1, 0, 0);
    si.tangent_sign = 1;
    const Bsdf b = make_bsdf(m, si, textures);
    CHECK(b.layers.on);
    CHECK(b.layers.clearcoat == doctest::Approx(0.4f));
    CHECK(b.layers.coat_roughness == doctest::Approx(0.15f));
    CHECK(b.layers.sheen.x == doctest::Approx(0.5f));
    CHECK(b.layers.sheen.y == doctest::Approx(0.125f));
    CHECK(b.layers.sheen.z == doctest::Approx(0.75f));
    CHECK(b.layers.sheen_roughness == doctest::Approx(0.2f));
    CHECK_FALSE(b.layers.coat_frame);  // no normal map anywhere: one frame

    // A normal-mapped base leaves the coat on the interpolated normal...
    m.normal_texture = 1;
    const Bsdf mapped = make_bsdf(m, si, textures);
    REQUIRE(mapped.layers.coat_frame);
    CHECK(mapped.frame.n.x > 0.1f);
    const Vec3 coat_world = mapped.frame.to_world(mapped.layers.coat_normal);
    CHECK(coat_world.z == doctest::Approx(1.0f).epsilon(1e-5));
    // ...unless the coat has its own map.
    m.normal_texture = -1;
    m.layers.clearcoat_normal_texture = 1;
    const Bsdf own = make_bsdf(m, si, textures);
    REQUIRE(own.layers.coat_frame);
    CHECK(own.frame.n.z == 1.0f);
    CHECK(own.frame.to_world(own.layers.coat_normal).x > 0.1f);
}
