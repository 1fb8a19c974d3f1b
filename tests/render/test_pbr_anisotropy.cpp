// KHR_materials_anisotropy in the pbr BSDF: the anisotropic GGX functions,
// energy, sampling against the reported density, the direction's frame, and
// the isotropic path left exactly as it was at strength 0.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pbr_test_util.h"
#include "render/bsdf_pbr.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc anisotropic(MaterialDesc m, float strength, float rotation = 0.0f) {
    m.anisotropy = strength;
    m.anisotropy_rotation = rotation;
    return m;
}

/// The BSDF of `m` on a surface facing +z whose tangent is +x (bitangent +y).
Bsdf bsdf_with_tangent(const MaterialDesc& m) {
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    si.tangent = Vec3(1, 0, 0);
    return make_bsdf(m, si, {});
}

/// Anisotropic materials over the roughnesses and strengths the tests cover.
std::vector<MaterialDesc> anisotropic_materials(Rgb base) {
    std::vector<MaterialDesc> out;
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.05f, 0.3f, 0.7f})
            for (float strength : {0.3f, 0.8f, 1.0f})
                out.push_back(anisotropic(pbr(base, metallic, roughness), strength, 0.4f));
    return out;
}

}  // namespace

TEST_CASE("anisotropic GGX with equal alphas agrees with the isotropic functions") {
    for (float alpha : {0.01f, 0.2f, 0.7f, 1.0f})
        for (float c : {0.95f, 0.5f, 0.1f})
            for (float phi : {0.0f, 1.0f, 2.5f}) {
                const Vec3 w = direction(c, phi), wi = direction(0.6f, phi + 2.0f);
                const Vec3 wm = normalize(w + wi);
                CHECK(ggx_d(wm, alpha, alpha) == doctest::Approx(ggx_d(wm, alpha)).epsilon(1e-4));
                CHECK(ggx_lambda(w, alpha, alpha) == doctest::Approx(ggx_lambda(w, alpha)).epsilon(1e-4));
                CHECK(ggx_reflection_pdf(w, wi, alpha, alpha) ==
                      doctest::Approx(ggx_reflection_pdf(w, wi, alpha)).epsilon(1e-4));
                CHECK(ggx_vndf_pdf(w, wm, alpha, alpha) ==
                      doctest::Approx(ggx_vndf_pdf(w, wm, alpha)).epsilon(1e-4));
            }
    // Stretching only x widens D along x: a half vector tilted along x is likelier.
    const Vec3 tilt_x = normalize(Vec3(0.3f, 0, 1)), tilt_y = normalize(Vec3(0, 0.3f, 1));
    CHECK(ggx_d(tilt_x, 0.5f, 0.1f) > 10.0f * ggx_d(tilt_y, 0.5f, 0.1f));
}

TEST_CASE("anisotropy 0 leaves the pbr BSDF bit for bit and the anisotropic path with equal alphas agrees") {
    for (const MaterialDesc& base : {pbr(Rgb(0.8f, 0.3f, 0.1f), 0.0f, 0.4f), pbr(Rgb(0.9f), 1.0f, 0.2f)}) {
        const MaterialDesc zero = anisotropic(base, 0.0f, 1.3f);  // a rotation alone switches nothing on
        const Bsdf plain = bsdf_with_tangent(base), off = bsdf_with_tangent(zero);
        CHECK_FALSE(off.anisotropic);
        // The anisotropic code path forced on with alpha_y = alpha computes the same BSDF.
        Bsdf forced = plain;
        forced.anisotropic = true;
        forced.alpha_y = forced.alpha;
        Sampler s(9, SamplerType::independent);
        s.start(0, 0, 0);
        for (int k = 0; k < 200; ++k) {
            const Vec3 wo = direction(0.05f + 0.9f * s.next_1d(), 6.0f * s.next_1d());
            const Vec3 wi = direction(2.0f * s.next_1d() - 1.0f, 6.0f * s.next_1d());
            float p_plain = 0, p_off = 0, p_forced = 0;
            const Rgb f_plain = eval_pbr(plain, wo, wi, &p_plain), f_off = eval_pbr(off, wo, wi, &p_off),
                      f_forced = eval_pbr(forced, wo, wi, &p_forced);
            CHECK(f_plain == f_off);
            CHECK(p_plain == p_off);
            for (int c = 0; c < 3; ++c)
                CHECK(f_forced[c] == doctest::Approx(f_plain[c]).epsilon(1e-4).scale(1e-6));
            CHECK(p_forced == doctest::Approx(p_plain).epsilon(1e-4).scale(1e-6));
            const Vec2 u = s.next_2d();
            const float u_lobe = s.next_1d();
            BsdfSample a, b;
            const bool ok_a = sample_pbr(plain, wo, u, u_lobe, a), ok_b = sample_pbr(off, wo, u, u_lobe, b);
            REQUIRE(ok_a == ok_b);
            if (ok_a) {
                CHECK(a.wi == b.wi);
                CHECK(a.weight == b.weight);
            }
        }
    }
}

TEST_CASE("anisotropic pbr reflection is reciprocal") {
    for (const MaterialDesc& m : anisotropic_materials(Rgb(0.9f, 0.4f, 0.1f))) {
        const Bsdf b = bsdf_with_tangent(m);
        REQUIRE(b.anisotropic);
        for (float c1 : {0.9f, 0.5f, 0.15f})
            for (float c2 : {0.8f, 0.3f}) {
                const Vec3 a = direction(c1, 0.2f), d = direction(c2, 2.1f);
                float pdf;
                const Rgb f_ad = eval_pbr(b, a, d, &pdf) / d.z, f_da = eval_pbr(b, d, a, &pdf) / a.z;
                INFO("metallic " << m.metallic << " roughness " << m.roughness << " strength "
                                 << m.anisotropy);
                for (int k = 0; k < 3; ++k) CHECK(f_ad[k] == doctest::Approx(f_da[k]).epsilon(1e-4));
                CHECK(max_component(f_ad) > 0);
            }
    }
}

TEST_CASE("white furnace: an anisotropic white pbr material keeps its energy at every angle") {
    // White metal and white dielectric over a white base reflect what they receive,
    // whichever way the anisotropy points and wherever the light comes from, up
    // to the anisotropic albedo table's error (-2% to +1%, most near grazing angles).
    const int n = scaled(8000);
    for (float metallic : {1.0f, 0.0f})
        for (float roughness : {0.05f, 0.3f, 0.6f, 1.0f})
            for (float strength : {0.5f, 0.9f, 1.0f})
                for (float rotation : {0.0f, 1.1f}) {
                    const Bsdf b = bsdf_with_tangent(
                        anisotropic(pbr(Rgb(1.0f), metallic, roughness), strength, rotation));
                    REQUIRE(b.anisotropic);
                    for (float cos_o : {1.0f, 0.7f, 0.3f, 0.1f})
                        for (float phi : {0.0f, 0.8f, 1.57f}) {
                            const Stat a = directional_albedo(b, b.frame.to_local(direction(cos_o, phi)), n);
                            INFO("metallic " << metallic << " roughness " << roughness << " strength "
                                             << strength << " rotation " << rotation << " cos_o " << cos_o
                                             << " phi " << phi << " albedo " << a.mean.x << " se " << a.se.x);
                            CHECK(a.mean.x <= 1.0f + 4.0f * a.se.x + 0.01f);
                            CHECK(a.mean.x >= 0.97f - 4.0f * a.se.x);
                        }
                }
}

TEST_CASE("anisotropic GGX visible-normal sampler follows its pdf (chi-square)") {
    const int n = scaled(200000);
    for (const auto& [ax, ay] : {std::pair{0.05f, 0.5f}, std::pair{0.6f, 0.1f}, std::pair{1.0f, 0.3f}})
        for (float cos_o : {0.9f, 0.4f})
            for (float phi : {0.0f, 0.7f}) {
                const Vec3 wo = direction(cos_o, phi);
                auto sample = [&](Sampler& s, Vec3& wi) {
                    wi = reflect(wo, sample_ggx_vndf(wo, ax, ay, s.next_2d()));
                    return wi.z > 0;
                };
                auto pdf = [&](const Vec3& wi) { return ggx_reflection_pdf(wo, wi, ax, ay); };
                const double z = chi2_deviate(n, sample, pdf);
                INFO("alpha " << ax << " x " << ay << " cos_o " << cos_o << " phi " << phi << " deviate "
                              << z);
                CHECK(z < 3.5);
            }
}

TEST_CASE("anisotropic pbr sampler follows the pdf eval_pbr reports (chi-square)") {
    const int n = scaled(200000);
    MaterialDesc glass = anisotropic(pbr(Rgb(0.9f), 0.0f, 0.3f), 0.7f, 0.5f);
    glass.transmission = 1.0f;
    for (const MaterialDesc& m : {anisotropic(pbr(Rgb(0.8f, 0.5f, 0.2f), 0.0f, 0.3f), 0.8f, 0.3f),
                                  anisotropic(pbr(Rgb(0.9f), 1.0f, 0.2f), 1.0f, 1.0f), glass})
        for (float cos_o : {0.8f, 0.3f}) {
            const Bsdf b = bsdf_with_tangent(m);
            const Vec3 wo = direction(cos_o, 1.0f);
            const double z = pbr_chi2_deviate(n, b, wo);
            INFO("metallic " << m.metallic << " transmission " << m.transmission << " cos_o " << cos_o
                             << " deviate " << z);
            CHECK(z < 3.5);
        }
}

TEST_CASE("anisotropic pdfs integrate to one and pbr to its sampler's success rate") {
    for (const auto& [ax, ay] : {std::pair{0.1f, 0.6f}, std::pair{0.8f, 0.2f}})
        for (float cos_o : {0.9f, 0.3f}) {
            const Vec3 wo = direction(cos_o, 0.5f);
            const double sum =
                upper_hemisphere_integral([&](const Vec3& wm) { return ggx_vndf_pdf(wo, wm, ax, ay); });
            CHECK(sum == doctest::Approx(1.0).epsilon(0.01));
        }
    for (float transmission : {0.0f, 1.0f}) {
        MaterialDesc m = anisotropic(pbr(Rgb(0.7f), 0.3f, 0.4f), 0.9f, 0.2f);
        m.transmission = transmission;
        const Bsdf b = bsdf_with_tangent(m);
        const Vec3 wo = direction(0.6f, 0.3f);
        const double integral = pbr_pdf_integral(b, wo);
        const double success = pbr_sample_success_rate(b, wo, 100000);
        INFO("transmission " << transmission);
        CHECK(integral == doctest::Approx(success).epsilon(0.01));
        CHECK(integral <= 1.01);
    }
}

TEST_CASE("anisotropy rotated by 90 degrees swaps the roles of tangent and bitangent") {
    const MaterialDesc m = pbr(Rgb(0.9f, 0.6f, 0.3f), 1.0f, 0.3f);
    const Bsdf along_t = bsdf_with_tangent(anisotropic(m, 0.8f, 0.0f));
    const Bsdf along_b = bsdf_with_tangent(anisotropic(m, 0.8f, 0.5f * kPi));
    CHECK(dot(along_t.frame.s, Vec3(1, 0, 0)) == doctest::Approx(1.0f));
    CHECK(dot(along_b.frame.s, Vec3(0, 1, 0)) == doctest::Approx(1.0f));
    const auto quarter_turn_back = [](const Vec3& w) { return Vec3(w.y, -w.x, w.z); };
    bool differs = false;
    for (float c1 : {0.9f, 0.4f})
        for (float c2 : {0.7f, 0.2f})
            for (float phi : {0.0f, 0.6f, 1.5f}) {
                const Vec3 wo = direction(c1, phi), wi = direction(c2, phi + 2.8f);
                float p1 = 0, p2 = 0;
                const Rgb f_b = eval_bsdf(along_b, wo, wi, &p1);
                const Rgb f_t = eval_bsdf(along_t, quarter_turn_back(wo), quarter_turn_back(wi), &p2);
                for (int c = 0; c < 3; ++c) CHECK(f_b[c] == doctest::Approx(f_t[c]).epsilon(1e-3));
                CHECK(p1 == doctest::Approx(p2).epsilon(1e-3));
                float p3 = 0;
                differs |= std::abs(eval_bsdf(along_t, wo, wi, &p3).x - f_b.x) > 0.05f * f_b.x;
            }
    CHECK(differs);  // the rotation changes something at all
    // A mirrored tangent frame (w = -1) turns the rotation the other way.
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    si.tangent = Vec3(1, 0, 0);
    si.tangent_sign = -1;
    const Bsdf mirrored = make_bsdf(anisotropic(m, 0.8f, 0.5f * kPi), si, {});
    CHECK(dot(mirrored.frame.s, Vec3(0, -1, 0)) == doctest::Approx(1.0f));
}

namespace {

/// Luminance-weighted spread (standard deviations in pixels, along image x and
/// y) of the pixels brighter than a tenth of the brightest.
std::pair<double, double> highlight_spread(const Film& film, int size) {
    float peak = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) peak = std::max(peak, luminance(film.mean(x, y)));
    double w = 0, mx = 0, my = 0, sxx = 0, syy = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double l = luminance(film.mean(x, y));
            if (l < 0.1 * double(peak)) continue;
            w += l;
            mx += l * x;
            my += l * y;
            sxx += l * x * x;
            syy += l * y * y;
        }
    mx /= w;
    my /= w;
    return {std::sqrt(sxx / w - mx * mx), std::sqrt(syy / w - my * my)};
}

/// A rough metal plane z = 0 seen straight down, lit by a point light beside the camera.
std::pair<double, double> highlight(float strength, float rotation, int size) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(anisotropic(pbr(Rgb(0.9f), 1.0f, 0.25f), strength, rotation));
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    d.lights.push_back({LightDesc::Type::point, {0, 0, 2}, {0, 0, -1}, Rgb(4.0f), Rgb(0.0f)});
    d.camera.position = {0, 0, 2};
    d.camera.look_at = {0, 0, 0};
    d.camera.up = {0, 1, 0};
    d.camera.vfov = 90;
    d.render.width = d.render.height = size;
    d.render.spp = 16;
    d.render.max_depth = 2;
    const Scene scene = build_scene(d);
    Film film(size, size);
    render_image(scene, film, RenderOptions{2, false});
    return highlight_spread(film, size);
}

}  // namespace

TEST_CASE("render: the highlight of an anisotropic plane stretches along the anisotropy direction") {
    const int size = 48;
    const auto [iso_x, iso_y] = highlight(0.0f, 0.0f, size);
    const auto [t_x, t_y] = highlight(0.7f, 0.0f, size);
    const auto [b_x, b_y] = highlight(0.7f, 0.5f * kPi, size);
    INFO("isotropic " << iso_x << " x " << iso_y << ", along the tangent " << t_x << " x " << t_y
                      << ", along the bitangent " << b_x << " x " << b_y);
    CHECK(iso_x == doctest::Approx(iso_y).epsilon(0.1));
    // A plane facing +z has no tangent: the x axis stands in, which this camera shows as image x.
    CHECK(t_x > 1.5 * t_y);
    CHECK(b_y > 1.5 * b_x);
    CHECK(t_x > 1.3 * iso_x);
}
