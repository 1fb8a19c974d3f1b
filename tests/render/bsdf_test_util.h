#pragma once
/// Helpers of the BSDF sampling tests: directions on the unit sphere and a
/// chi-square test of a sampler against the density it claims.
#include <algorithm>
#include <cmath>
#include <vector>

#include "math/sampling.h"
#include "render/bsdf.h"
#include "render/sampler.h"

namespace sahara::test {

inline MaterialDesc pbr(Rgb base, float metallic, float roughness) {
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = base;
    m.metallic = metallic;
    m.roughness = roughness;
    return m;
}

/// The BSDF of `m` on a surface facing +z (local frame = world frame).
inline Bsdf bsdf_of(const MaterialDesc& m) {
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    return make_bsdf(m, si, {});
}

inline Vec3 direction(float cos_theta, float phi) {
    const float s = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

/// Wilson-Hilferty: the chi-square statistic as a standard normal deviate.
inline double chi2_z(double chi2, int dof) {
    const double k = dof;
    return (std::cbrt(chi2 / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
}

inline constexpr int kThetaBins = 20, kPhiBins = 40;

/// Chi-square statistic of `n` samples against the density `pdf` over the
/// sphere binned in (cos theta, phi); bins expecting fewer than 5 are pooled.
/// Returns the normal deviate (large: the sampler does not follow the pdf).
template <class Sample, class Pdf>
inline double chi2_deviate(int n, Sample&& sample, Pdf&& pdf) {
    std::vector<double> observed(kThetaBins * kPhiBins, 0.0), expected(kThetaBins * kPhiBins, 0.0);
    Sampler sampler(11, SamplerType::independent);
    sampler.start(0, 0, 0);
    for (int i = 0; i < n; ++i) {
        Vec3 w;
        if (!sample(sampler, w)) continue;
        const float phi = std::atan2(w.y, w.x) + kPi;
        const int ti = std::clamp(int((w.z + 1.0f) * 0.5f * kThetaBins), 0, kThetaBins - 1);
        const int pi = std::clamp(int(phi / (2 * kPi) * kPhiBins), 0, kPhiBins - 1);
        observed[size_t(ti * kPhiBins + pi)] += 1;
    }
    constexpr int kSub = 16;  // midpoint rule inside each bin
    for (int ti = 0; ti < kThetaBins; ++ti)
        for (int pi = 0; pi < kPhiBins; ++pi) {
            double sum = 0;
            for (int a = 0; a < kSub; ++a)
                for (int b = 0; b < kSub; ++b) {
                    const float c = -1.0f + 2.0f * (float(ti) + (float(a) + 0.5f) / kSub) / kThetaBins;
                    const float phi = 2 * kPi * (float(pi) + (float(b) + 0.5f) / kSub) / kPhiBins - kPi;
                    sum += double(pdf(direction(c, phi)));
                }
            const double bin_area = (2.0 / kThetaBins) * (2.0 * double(kPi) / kPhiBins);
            expected[size_t(ti * kPhiBins + pi)] = sum / (kSub * kSub) * bin_area * n;
        }
    double chi2 = 0, pool_o = 0, pool_e = 0;
    int dof = 0;
    for (size_t k = 0; k < observed.size(); ++k) {
        if (expected[k] < 5) {
            pool_o += observed[k];
            pool_e += expected[k];
            continue;
        }
        chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
        ++dof;
    }
    if (pool_e >= 5) {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        ++dof;
    } else if (pool_o > 20) {
        return 1e9;  // samples where the pdf says there should be none
    }
    return chi2_z(chi2, std::max(1, dof - 1));
}

}  // namespace sahara::test
