#pragma once
/// Checks shared by the pbr BSDF tests (base, layers, anisotropy): the sampler
/// against the pdf eval_pbr reports, that pdf's integral, the directional albedo.
#include "bsdf_test_util.h"
#include "render/bsdf_pbr.h"
#include "render_test_util.h"

namespace sahara::test {

/// chi2_deviate of sample_pbr's directions at wo against eval_pbr's pdf.
inline double pbr_chi2_deviate(int n, const Bsdf& b, const Vec3& wo) {
    auto sample = [&](Sampler& s, Vec3& wi) {
        BsdfSample bs;
        const Vec2 u = s.next_2d();
        if (!sample_pbr(b, wo, u, s.next_1d(), bs)) return false;
        wi = bs.wi;
        return true;
    };
    auto pdf = [&](const Vec3& wi) {
        float p = 0;
        eval_pbr(b, wo, wi, &p);
        return p;
    };
    return chi2_deviate(n, sample, pdf);
}

/// f integrated over the upper hemisphere (stratified cos theta x phi grid).
template <class F>
inline double upper_hemisphere_integral(F&& f) {
    constexpr int kN = 400;
    double sum = 0;
    for (int i = 0; i < kN; ++i)
        for (int j = 0; j < kN; ++j)
            sum += double(f(direction((float(i) + 0.5f) / kN, 2 * kPi * (float(j) + 0.5f) / kN)));
    return sum * (2 * double(kPi)) / (double(kN) * kN);
}

/// eval_pbr's pdf at wo integrated over the sphere (stratified cos theta x phi grid):
/// the share of samples sample_pbr returns, when the two agree.
inline double pbr_pdf_integral(const Bsdf& b, const Vec3& wo) {
    constexpr int kN = 400;
    double integral = 0;
    for (int i = 0; i < 2 * kN; ++i)
        for (int j = 0; j < kN; ++j) {
            float p = 0;
            eval_pbr(b, wo, direction(-1.0f + (float(i) + 0.5f) / kN, 2 * kPi * (float(j) + 0.5f) / kN), &p);
            integral += double(p);
        }
    return integral * 4 * double(kPi) / (2.0 * kN * kN);
}

/// The share of n calls of sample_pbr at wo that return a direction.
inline double pbr_sample_success_rate(const Bsdf& b, const Vec3& wo, int n) {
    Sampler s(3, SamplerType::independent);
    s.start(0, 0, 0);
    int ok = 0;
    for (int k = 0; k < n; ++k) {
        BsdfSample bs;
        const Vec2 u = s.next_2d();
        ok += sample_pbr(b, wo, u, s.next_1d(), bs) ? 1 : 0;
    }
    return double(ok) / n;
}

/// Directional albedo at wo by importance sampling: mean and standard error of
/// the sample weights (a failed sample counts zero).
inline Stat directional_albedo(const Bsdf& b, const Vec3& wo, int n) {
    return sample_stats(n, 5, [&](Sampler& s) {
        BsdfSample bs;
        const Vec2 u = s.next_2d();
        return sample_pbr(b, wo, u, s.next_1d(), bs) ? bs.weight : Rgb(0.0f);
    });
}

}  // namespace sahara::test
