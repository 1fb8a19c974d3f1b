// KHR_materials_iridescence in the pbr BSDF: the thin-film reflectance against a
// direct Airy summation, the material left bit for bit without a film, energy,
// reciprocity, and sampling against the reported density with a film.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "pbr_test_util.h"
#include "render/bsdf_pbr.h"
#include "render/thin_film.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc iridescent(MaterialDesc m, float factor, float ior, float thickness) {
    m.iridescence.factor = factor;
    m.iridescence.ior = ior;
    m.iridescence.thickness_max = thickness;
    return m;
}

/// One lobe of the CIE 1931 colour matching functions' multi-lobe Gaussian fit
/// (Wyman, Sloan and Shirley 2013): widths s1 below the mean, s2 above.
double lobe(double lambda, double mu, double s1, double s2) {
    const double t = (lambda - mu) / (lambda < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}

Vec3d cie_xyz(double l) {
    return {1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
                0.065 * lobe(l, 501.1, 20.4, 26.2),
            0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
            1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8)};
}

/// Reflectance at normal incidence of a film (ior n2, thickness d nm) between
/// air and a base of ior n3, summed over all its inner reflections (Airy's
/// formula with complex amplitudes), per wavelength 360-830 nm, weighted by
/// the colour matching functions (each normalised so that a reflectance of 1
/// gives XYZ (1, 1, 1), as the extension's sensitivities are) and taken to
/// linear Rec.709 RGB. The channel `c` of that, for a base of ior n3.
double airy_rgb(double n2, double d, double n3, int c) {
    const double r12 = (1.0 - n2) / (1.0 + n2), r23 = (n2 - n3) / (n2 + n3);
    Vec3d xyz(0.0), norm(0.0);
    for (int l = 360; l <= 830; ++l) {
        const std::complex<double> e = std::polar(1.0, 4.0 * M_PI * n2 * d / l);
        const double r = std::norm((r12 + r23 * e) / (1.0 + r12 * r23 * e));
        const Vec3d w = cie_xyz(l);
        xyz += w * r;
        norm += w;
    }
    xyz = Vec3d(xyz.x / norm.x, xyz.y / norm.y, xyz.z / norm.z);
    const double m[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                            {-0.9692660, 1.8760108, 0.0415560},
                            {0.0556434, -0.2040259, 1.0572252}};
    return m[c][0] * xyz.x + m[c][1] * xyz.y + m[c][2] * xyz.z;
}

float f0_of_ior(float ior) { return ((ior - 1) / (ior + 1)) * ((ior - 1) / (ior + 1)); }

}  // namespace

TEST_CASE("thin film at normal incidence matches a direct Airy summation integrated to RGB") {
    // The extension's model differs from the exact sum by its own Gaussian fit
    // of the colour matching functions (up to 0.005 where no interference
    // happens: d = 0 gives 0.0437 against 0.0482 in red) and by cutting the
    // series after two interference terms, whose neglected rest grows with
    // sqrt(R12 R23): below 0.001 for a film of ior 1.3, up to 0.02 for 1.8-2.0.
    // A film at the wrong phase (pi off) or the wrong thickness misses by 0.03 or more.
    struct Case {
        float film_ior, thickness, base_ior;
        double tolerance;
    };
    for (const Case& k :
         {Case{1.3f, 0, 1.5f, 0.006}, Case{1.3f, 250, 1.5f, 0.006}, Case{1.3f, 400, 1.5f, 0.006},
          Case{1.3f, 600, 1.6f, 0.006}, Case{1.8f, 300, 1.5f, 0.025}, Case{2.0f, 500, 1.5f, 0.025}}) {
        const Rgb model = thin_film_reflectance(1.0f, k.film_ior, k.thickness, Rgb(f0_of_ior(k.base_ior)));
        for (int c = 0; c < 3; ++c) {
            // Saturated film colours fall outside Rec.709; the model clamps them to [0, 1], so does this.
            const double exact = std::clamp(airy_rgb(k.film_ior, k.thickness, k.base_ior, c), 0.0, 1.0);
            INFO("film ior " << k.film_ior << " thickness " << k.thickness << " base ior " << k.base_ior
                             << " channel " << c << " model " << model[c] << " Airy " << exact);
            CHECK(std::abs(double(model[c]) - exact) <= k.tolerance);
        }
    }
    // The test resolves thickness: 250 and 400 nm differ by far more than the tolerance.
    CHECK(std::abs(airy_rgb(1.3, 250, 1.5, 0) - airy_rgb(1.3, 400, 1.5, 0)) > 0.03);
}

TEST_CASE("thin film reflectance stays in [0 1] and its colour moves with thickness and angle") {
    const Rgb dielectric(0.04f), gold(0.95f, 0.65f, 0.25f);
    for (const Rgb& base : {dielectric, gold})
        for (float ior : {1.0f, 1.3f, 2.0f, 3.0f})
            for (float thickness : {1.0f, 100.0f, 300.0f, 800.0f, 3000.0f})
                for (float c = 0.0f; c <= 1.0f; c += 0.05f) {
                    const Rgb r = thin_film_reflectance(c, ior, thickness, base);
                    for (int k = 0; k < 3; ++k) {
                        CHECK(r[k] >= 0.0f);
                        CHECK(r[k] <= 1.0f);
                    }
                }
    // Head-on, over 250 nm and over 400 nm of a 1.3 film on glass: red-orange and green.
    const Rgb thin = thin_film_reflectance(1.0f, 1.3f, 250.0f, dielectric);
    const Rgb thick = thin_film_reflectance(1.0f, 1.3f, 400.0f, dielectric);
    CHECK(thin.x > thin.z + 0.02f);
    CHECK(thick.y > thick.x + 0.02f);
    // Tilting shortens the path difference: the colour shifts.
    const Rgb tilted = thin_film_reflectance(0.5f, 1.3f, 400.0f, dielectric);
    CHECK(length(tilted - thick) > 0.01f);
    // Past the critical angle of a film less dense than outside, everything reflects.
    CHECK(thin_film_reflectance(0.1f, 1.1f, 300.0f, dielectric, 1.5f) == Rgb(1.0f));
    // The bound holds at normal incidence for every thickness.
    for (float ior : {1.3f, 1.8f, 2.5f, 3.0f}) {
        const float bound = thin_film_reflectance_bound(ior, dielectric);
        for (float d = 10.0f; d <= 1500.0f; d += 5.0f)
            CHECK(max_component(thin_film_reflectance(1.0f, ior, d, dielectric)) <= bound);
    }
}

TEST_CASE("iridescence factor 0 or thickness 0 leaves the pbr BSDF bit for bit") {
    for (const MaterialDesc& base : {pbr(Rgb(0.8f, 0.4f, 0.2f), 0.0f, 0.3f),
                                     pbr(Rgb(0.9f, 0.7f, 0.3f), 1.0f, 0.5f), pbr(Rgb(0.6f), 0.5f, 0.05f)}) {
        const Bsdf plain = bsdf_of(base);
        for (const MaterialDesc& m :
             {iridescent(base, 0.0f, 1.8f, 400.0f), iridescent(base, 1.0f, 1.8f, 0.0f)}) {
            const Bsdf b = bsdf_of(m);
            CHECK_FALSE(b.iridescent);
            for (float cos_o : {0.9f, 0.4f, 0.1f})
                for (float cos_i : {0.95f, 0.5f, 0.05f})
                    for (float phi : {0.0f, 1.3f, 3.0f}) {
                        const Vec3 wo = direction(cos_o, 0.2f), wi = direction(cos_i, phi);
                        float p0 = 0, p1 = 0;
                        const Rgb f0 = eval_pbr(plain, wo, wi, &p0), f1 = eval_pbr(b, wo, wi, &p1);
                        CHECK(f0 == f1);
                        CHECK(p0 == p1);
                        BsdfSample s0, s1;
                        const bool ok0 = sample_pbr(plain, wo, Vec2(cos_i, phi / 3.2f), cos_o, s0);
                        const bool ok1 = sample_pbr(b, wo, Vec2(cos_i, phi / 3.2f), cos_o, s1);
                        CHECK(ok0 == ok1);
                        if (ok0 && ok1) {
                            CHECK(s0.wi == s1.wi);
                            CHECK(s0.weight == s1.weight);
                        }
                        CHECK(pbr_fresnel(plain, cos_o) == pbr_fresnel(b, cos_o));
                    }
        }
    }
}

TEST_CASE("iridescence colours the specular lobe and keeps it reciprocal") {
    const MaterialDesc base = pbr(Rgb(0.0f), 0.0f, 0.2f);
    const Bsdf plain = bsdf_of(base), film = bsdf_of(iridescent(base, 1.0f, 1.8f, 300.0f));
    CHECK(film.iridescent);
    const Vec3 wo = direction(0.9f, 0.0f), mirror(-wo.x, -wo.y, wo.z);
    float pdf = 0;
    const Rgb f_plain = eval_pbr(plain, wo, mirror, &pdf), f_film = eval_pbr(film, wo, mirror, &pdf);
    // A black dielectric reflects a grey highlight; the film colours it.
    CHECK(max_component(f_plain) - min_component(f_plain) < 1e-4f * max_component(f_plain));
    CHECK(max_component(f_film) - min_component(f_film) > 0.3f * max_component(f_film));
    for (const MaterialDesc& m : {iridescent(pbr(Rgb(0.5f, 0.3f, 0.2f), 0.0f, 0.4f), 0.7f, 1.5f, 350.0f),
                                  iridescent(pbr(Rgb(0.9f, 0.6f, 0.3f), 1.0f, 0.3f), 1.0f, 2.0f, 500.0f)}) {
        const Bsdf b = bsdf_of(m);
        for (float c1 : {0.9f, 0.5f, 0.2f})
            for (float c2 : {0.8f, 0.3f})
                for (float phi : {0.5f, 2.0f}) {
                    const Vec3 a = direction(c1, 0.0f), bb = direction(c2, phi);
                    float p = 0;
                    // eval is f cos(theta_i): divide it out on each side.
                    const Rgb fab = eval_pbr(b, a, bb, &p) / bb.z, fba = eval_pbr(b, bb, a, &p) / a.z;
                    for (int k = 0; k < 3; ++k) CHECK(fab[k] == doctest::Approx(fba[k]).epsilon(1e-4));
                }
    }
}

TEST_CASE("white furnace: an iridescent white pbr material creates no energy") {
    const int n = scaled(20000);
    for (float metallic : {0.0f, 1.0f, 0.5f})
        for (float roughness : {0.05f, 0.3f, 0.8f})
            for (const auto& [ior, thickness] :
                 {std::pair{1.3f, 400.0f}, std::pair{2.2f, 250.0f}, std::pair{1.8f, 900.0f}}) {
                const Bsdf b = bsdf_of(iridescent(pbr(Rgb(1.0f), metallic, roughness), 1.0f, ior, thickness));
                for (float cos_o : {1.0f, 0.6f, 0.25f, 0.08f}) {
                    const Stat a = directional_albedo(b, direction(cos_o, 0.4f), n);
                    INFO("metallic " << metallic << " roughness " << roughness << " ior " << ior
                                     << " thickness " << thickness << " cos_o " << cos_o << " albedo "
                                     << a.mean.x << " " << a.mean.y << " " << a.mean.z);
                    for (int c = 0; c < 3; ++c) CHECK(a.mean[c] <= 1.0f + 4.0f * a.se[c] + 0.005f);
                    CHECK(min_component(a.mean) > 0.5f);
                }
            }
}

TEST_CASE("iridescent pbr sampler follows the pdf eval_pbr reports") {
    const int n = scaled(200000);
    MaterialDesc glass = iridescent(pbr(Rgb(0.9f), 0.0f, 0.3f), 1.0f, 1.6f, 300.0f);
    glass.transmission = 1.0f;
    for (const MaterialDesc& m : {iridescent(pbr(Rgb(0.8f, 0.5f, 0.2f), 0.0f, 0.3f), 1.0f, 2.0f, 400.0f),
                                  iridescent(pbr(Rgb(0.9f), 1.0f, 0.15f), 0.8f, 1.3f, 250.0f), glass})
        for (float cos_o : {0.8f, 0.3f}) {
            const Bsdf b = bsdf_of(m);
            const Vec3 wo = direction(cos_o, 1.0f);
            const double z = pbr_chi2_deviate(n, b, wo);
            const double integral = pbr_pdf_integral(b, wo);
            const double success = pbr_sample_success_rate(b, wo, 100000);
            INFO("metallic " << m.metallic << " transmission " << m.transmission << " cos_o " << cos_o
                             << " deviate " << z << " integral " << integral << " success " << success);
            CHECK(z < 3.5);
            CHECK(integral == doctest::Approx(success).epsilon(0.01));
            CHECK(integral <= 1.01);
        }
}

TEST_CASE("iridescence under a clearcoat has the coat outside the film") {
    // A 1.3 film on glass: from air its first interface is 1.0/1.3, under the
    // coat 1.5/1.3 (weaker, and reflecting off the less dense side: the
    // phase flips), so the highlight's colour changes.
    MaterialDesc m = iridescent(pbr(Rgb(0.0f), 0.0f, 0.2f), 1.0f, 1.3f, 400.0f);
    const Bsdf in_air = bsdf_of(m);
    m.layers.clearcoat = 1.0f;
    const Bsdf coated = bsdf_of(m);
    CHECK(coated.film.coat == 1.0f);
    const float cos_air = 0.8f;
    // The light reaches the film at the angle refracted into the coat.
    const float cos_coat = std::sqrt(1.0f - (1.0f - cos_air * cos_air) / (1.5f * 1.5f));
    const Rgb expected = thin_film_reflectance(cos_coat, 1.3f, 400.0f, Rgb(0.04f), 1.5f);
    const Rgb f_coated = pbr_fresnel(coated, cos_air), f_air = pbr_fresnel(in_air, cos_air);
    for (int c = 0; c < 3; ++c) CHECK(f_coated[c] == doctest::Approx(expected[c]).epsilon(1e-5));
    CHECK(length(f_coated - f_air) > 0.01f);
    // A half coat mixes the two.
    m.layers.clearcoat = 0.5f;
    const Rgb f_half = pbr_fresnel(bsdf_of(m), cos_air);
    for (int c = 0; c < 3; ++c)
        CHECK(f_half[c] == doctest::Approx(0.5f * (f_air[c] + f_coated[c])).epsilon(1e-4));
    // The bound the layering relies on also holds with the coat outside.
    for (float ior : {1.2f, 1.3f, 1.8f, 2.5f, 3.0f}) {
        const float bound = thin_film_reflectance_bound(ior, Rgb(0.04f), 1.5f);
        for (float d = 10.0f; d <= 1500.0f; d += 5.0f)
            CHECK(max_component(thin_film_reflectance(1.0f, ior, d, Rgb(0.04f), 1.5f)) <= bound);
    }
}

// The coat's layering scales what is below by what the coat reflects at wo
// only (render/bsdf_layers.h), so coated materials are not reciprocal: no check of that here.
TEST_CASE("iridescence under a clearcoat stays energy conserving and samples its pdf") {
    const int n = scaled(20000);
    for (float metallic : {0.0f, 1.0f})
        for (const auto& [ior, thickness] : {std::pair{1.3f, 400.0f}, std::pair{2.0f, 300.0f}})
            for (float clearcoat : {1.0f, 0.5f}) {
                MaterialDesc m = iridescent(pbr(Rgb(1.0f), metallic, 0.3f), 1.0f, ior, thickness);
                m.layers.clearcoat = clearcoat;
                m.layers.clearcoat_roughness = 0.1f;
                const Bsdf b = bsdf_of(m);
                INFO("metallic " << metallic << " ior " << ior << " clearcoat " << clearcoat);
                for (float cos_o : {1.0f, 0.5f, 0.1f}) {
                    const Stat a = directional_albedo(b, direction(cos_o, 0.4f), n);
                    INFO("cos_o " << cos_o << " albedo " << a.mean.x << " " << a.mean.y << " " << a.mean.z);
                    for (int c = 0; c < 3; ++c) CHECK(a.mean[c] <= 1.0f + 4.0f * a.se[c] + 0.005f);
                }
                const Vec3 wo = direction(0.6f, 1.0f);
                CHECK(pbr_chi2_deviate(scaled(100000), b, wo) < 3.5);
                CHECK(pbr_pdf_integral(b, wo) ==
                      doctest::Approx(pbr_sample_success_rate(b, wo, 50000)).epsilon(0.01));
            }
}
