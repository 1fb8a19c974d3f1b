#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "render/bsdf_pbr.h"
#include "render/ggx_albedo.h"
#include "pbr_test_util.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

TEST_CASE("GGX visible-normal sampler follows its pdf (chi-square)") {
    const int n = scaled(200000);
    for (float alpha : {0.05f, 0.2f, 0.5f, 1.0f})
        for (float cos_o : {0.95f, 0.6f, 0.2f}) {
            const Vec3 wo = direction(cos_o, 0.3f);
            auto sample = [&](Sampler& s, Vec3& wi) {
                wi = reflect(wo, sample_ggx_vndf(wo, alpha, s.next_2d()));
                return wi.z > 0;
            };
            auto pdf = [&](const Vec3& wi) { return ggx_reflection_pdf(wo, wi, alpha); };
            const double z = chi2_deviate(n, sample, pdf);
            INFO("alpha " << alpha << " cos_o " << cos_o << " deviate " << z);
            CHECK(z < 3.5);
        }
}

TEST_CASE("pbr sampler follows the pdf eval_pbr reports (chi-square)") {
    const int n = scaled(200000);
    struct Case {
        MaterialDesc m;
        float cos_o;
    };
    MaterialDesc glass = pbr(Rgb(0.9f), 0.0f, 0.4f);
    glass.transmission = 1.0f;
    const Case cases[] = {{pbr(Rgb(0.8f, 0.5f, 0.2f), 0.0f, 0.3f), 0.8f},
                          {pbr(Rgb(0.8f, 0.5f, 0.2f), 1.0f, 0.5f), 0.4f},
                          {pbr(Rgb(0.5f), 0.5f, 0.8f), 0.25f},
                          {glass, 0.7f}};
    for (const Case& c : cases) {
        const Bsdf b = bsdf_of(c.m);
        const Vec3 wo = direction(c.cos_o, 1.0f);
        const double z = pbr_chi2_deviate(n, b, wo);
        INFO("metallic " << c.m.metallic << " roughness " << c.m.roughness << " deviate " << z);
        CHECK(z < 3.5);
    }
}

TEST_CASE("pdfs integrate to one: visible normals exactly, pbr to its sampler's success rate") {
    for (float alpha : {0.1f, 0.4f, 1.0f})
        for (float cos_o : {0.9f, 0.3f}) {
            const Vec3 wo = direction(cos_o, 0.0f);
            const double sum =
                upper_hemisphere_integral([&](const Vec3& wm) { return ggx_vndf_pdf(wo, wm, alpha); });
            CHECK(sum == doctest::Approx(1.0).epsilon(0.01));
        }
    for (float roughness : {0.3f, 0.7f})
        for (float transmission : {0.0f, 1.0f}) {
            MaterialDesc m = pbr(Rgb(0.7f), 0.3f, roughness);
            m.transmission = transmission;
            const Bsdf b = bsdf_of(m);
            const Vec3 wo = direction(0.6f, 0.0f);
            const double integral = pbr_pdf_integral(b, wo);
            const double success = pbr_sample_success_rate(b, wo, 100000);
            INFO("roughness " << roughness << " transmission " << transmission);
            CHECK(integral == doctest::Approx(success).epsilon(0.01));
            CHECK(integral <= 1.01);
        }
}

TEST_CASE("pbr reflection is reciprocal: f(wo, wi) = f(wi, wo)") {
    for (const MaterialDesc& m : {pbr(Rgb(0.9f, 0.4f, 0.1f), 0.0f, 0.35f),
                                  pbr(Rgb(0.9f, 0.4f, 0.1f), 1.0f, 0.6f), pbr(Rgb(0.3f), 0.5f, 1.0f)}) {
        const Bsdf b = bsdf_of(m);
        for (float c1 : {0.9f, 0.5f, 0.15f})
            for (float c2 : {0.8f, 0.3f}) {
                const Vec3 a = direction(c1, 0.2f), d = direction(c2, 2.5f);
                float pdf;
                const Rgb f_ad = eval_pbr(b, a, d, &pdf) / d.z, f_da = eval_pbr(b, d, a, &pdf) / a.z;
                for (int k = 0; k < 3; ++k) CHECK(f_ad[k] == doctest::Approx(f_da[k]).epsilon(1e-4));
                CHECK(max_component(f_ad) > 0);
            }
    }
}

TEST_CASE("GGX albedo table: white metal loses energy without compensation and E_avg matches") {
    const GgxAlbedoTable& t = GgxAlbedoTable::get();
    CHECK(t.at(1.0f, 0.0f).e == doctest::Approx(1.0f).epsilon(1e-3));
    CHECK(t.at(0.5f, 1.0f).e < 0.8f);  // rough GGX loses a good part to multiple scattering
    CHECK(t.at(0.5f, 1.0f).e > 0.4f);
    CHECK(t.average(1.0f).e < t.average(0.5f).e);
    // The same table at a finer quadrature agrees: the integration has converged.
    const GgxAlbedoTable fine(64);
    for (float mu : {0.1f, 0.5f, 1.0f})
        for (float r : {0.2f, 0.6f, 1.0f})
            CHECK(fine.at(mu, r).e == doctest::Approx(t.at(mu, r).e).epsilon(2e-3));
}

namespace {

Scene pbr_sphere_in_furnace(const MaterialDesc& m) {
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials.push_back(m);
    d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
    return build_scene(d);
}

}  // namespace

TEST_CASE("white furnace: a white pbr sphere stays white at every roughness, dielectric or metal") {
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
            const Scene scene = pbr_sphere_in_furnace(pbr(Rgb(1.0f), metallic, roughness));
            for (float x : {0.0f, 0.5f, 0.8f, 0.95f}) {
                const Ray ray{{x, -5, 0.1f}, {0, 1, 0}, 0.0f, kInfinity, 0.0f};
                const Stat s = radiance_stats(scene, ray, scaled(4000), 16);
                INFO("metallic " << metallic << " roughness " << roughness << " x " << x << " mean "
                                 << s.mean.x << " se " << s.se.x);
                CHECK(within(s, Rgb(1.0f), 3, 0.01f));
            }
        }
}

TEST_CASE("furnace: grey dielectric pbr reflects its base plus the specular layer") {
    // Head-on (mu = 1) the model predicts: the dielectric layer reflects
    // Ed = F0 E + (1 - F0) Es + (1 - E) F_ms (single plus compensated multiple
    // scattering), and the base reflects its albedo 0.5 of the rest.
    const GgxAlbedoTable& table = GgxAlbedoTable::get();
    for (float roughness : {0.2f, 0.8f}) {
        const GgxAlbedo e = table.at(1.0f, roughness), avg = table.average(roughness);
        const float f0 = 0.04f, f_avg = f0 + (1 - f0) / 21;
        const float f_ms = f_avg * f_avg * avg.e / (1 - f_avg * (1 - avg.e));
        const float ed = f0 * e.e + (1 - f0) * e.e_schlick + (1 - e.e) * f_ms;
        const float predicted = ed + 0.5f * (1 - ed);
        CHECK(predicted > 0.5f);
        CHECK(predicted < 0.53f);
        const Scene scene = pbr_sphere_in_furnace(pbr(Rgb(0.5f), 0.0f, roughness));
        const Stat s =
            radiance_stats(scene, Ray{{0, -5, 0}, {0, 1, 0}, 0.0f, kInfinity, 0.0f}, scaled(4000), 16);
        INFO("roughness " << roughness << " predicted " << predicted << " mean " << s.mean.x);
        CHECK(within(s, Rgb(predicted), 4, 0.003f));
    }
}
