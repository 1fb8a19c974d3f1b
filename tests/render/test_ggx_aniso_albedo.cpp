// The anisotropic GGX albedo table behind the pbr BSDF's multiple-scattering
// compensation under KHR_materials_anisotropy: its entries against a direct
// integration, its average against its own interpolation, its symmetries.
#include <doctest/doctest.h>

#include <cmath>

#include "pbr_test_util.h"
#include "render/ggx.h"
#include "render/ggx_aniso_albedo.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// E towards wo by importance sampling the visible normals with independent
/// samples: each weighs G2 / G1(wo).
double reference_albedo(const Vec3& wo, float ax, float ay, int n) {
    Sampler s(17, SamplerType::independent);
    s.start(0, 0, 0);
    const double lo = ggx_lambda(wo, ax, ay);
    double sum = 0;
    for (int k = 0; k < n; ++k) {
        const Vec3 wi = reflect(wo, sample_ggx_vndf(wo, ax, ay, s.next_2d()));
        if (wi.z > 0) sum += (1 + lo) / (1 + lo + double(ggx_lambda(wi, ax, ay)));
    }
    return sum / n;
}

}  // namespace

TEST_CASE("anisotropic GGX albedo table follows the albedo across azimuths and alphas") {
    const GgxAnisoAlbedoTable& t = GgxAnisoAlbedoTable::get();
    for (const auto& [ax, ay] : {std::pair{0.09f, 0.0025f}, std::pair{0.5f, 0.09f}, std::pair{1.0f, 0.0025f},
                                 std::pair{1.0f, 0.36f}})
        for (float c : {0.9f, 0.5f, 0.2f})
            for (float phi : {0.0f, 0.7f, 1.5f}) {
                const Vec3 wo = direction(c, phi);
                const double ref = reference_albedo(wo, ax, ay, 40000);
                INFO("alpha " << ax << " x " << ay << " cos " << c << " phi " << phi << " reference " << ref);
                CHECK(t.at(wo, ax, ay).e == doctest::Approx(ref).epsilon(0.015));
                // Mirror images and the quarter turn with swapped alphas are the same lobe.
                CHECK(t.at(Vec3(-wo.x, -wo.y, wo.z), ax, ay).e == t.at(wo, ax, ay).e);
                CHECK(t.at(Vec3(wo.y, wo.x, wo.z), ay, ax).e == doctest::Approx(t.at(wo, ax, ay).e));
            }
    // At a grazing angle the albedo depends strongly on the azimuth: no single
    // isotropic alpha could stand in for both directions.
    const float along_rough = t.at(direction(0.2f, 0.0f), 1.0f, 0.01f).e;
    const float along_smooth = t.at(direction(0.2f, 0.5f * kPi), 1.0f, 0.01f).e;
    CHECK(std::abs(along_rough - along_smooth) > 0.2f);
}

TEST_CASE("anisotropic GGX albedo average is the cosine-weighted mean of the interpolated table") {
    // The compensation lobe (1 - E(wo)) (1 - E(wi)) / (pi (1 - E_avg)) integrates
    // over wi to exactly 1 - E(wo) only if E_avg is this mean.
    const GgxAnisoAlbedoTable& t = GgxAnisoAlbedoTable::get();
    for (const auto& [ax, ay] : {std::pair{0.2f, 0.004f}, std::pair{0.7f, 0.15f}, std::pair{1.0f, 0.5f}}) {
        const double e = upper_hemisphere_integral([&](const Vec3& w) { return t.at(w, ax, ay).e * w.z; });
        const double es =
            upper_hemisphere_integral([&](const Vec3& w) { return t.at(w, ax, ay).e_schlick * w.z; });
        INFO("alpha " << ax << " x " << ay);
        CHECK(t.average(ax, ay).e == doctest::Approx(e / double(kPi)).epsilon(1e-3));
        CHECK(t.average(ax, ay).e_schlick == doctest::Approx(es / double(kPi)).epsilon(2e-3));
    }
}
