#include "render/sheen.h"

#include <algorithm>
#include <cmath>

#include "math/sampling.h"
#include "render/ggx_albedo.h"

namespace sahara {

namespace {

/// The fitted exponent L(x) of the sheen Lambda: a / (1 + b x^c) + d x + e,
/// its coefficients blended between the published alpha = 0 and alpha = 1 fits
/// by (1 - alpha)^2.
float sheen_l(float x, float alpha) {
    const float t = (1.0f - alpha) * (1.0f - alpha);
    auto mix = [t](float at0, float at1) { return at0 * t + at1 * (1.0f - t); };
    const float a = mix(25.3245f, 21.5473f), b = mix(3.32435f, 3.82987f), c = mix(0.16801f, 0.19823f);
    const float d = mix(-1.27393f, -1.97760f), e = mix(-4.85967f, -4.32054f);
    return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}

/// E(mu) = integral of sheen_lobe over the hemisphere, on a midpoint grid in
/// theta (finer towards the horizon than a grid in cos theta, where the lobe
/// lives at low roughness) and phi over half the circle (the lobe is symmetric).
/// The masking terms depend on the two cosines only, so they leave the inner loop.
double integrate_albedo(float mu, float alpha, int steps) {
    mu = std::max(mu, 1e-4f);
    const Vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
    const float lambda_o = sheen_lambda(mu, alpha);
    const double d_theta = 0.5 * double(kPi) / steps, d_phi = double(kPi) / steps;
    double sum = 0;
    for (int i = 0; i < steps; ++i) {
        const double theta = (i + 0.5) * d_theta;
        const float sin_t = float(std::sin(theta)), cos_t = float(std::cos(theta));
        const float masking = 4.0f * mu * (1.0f + lambda_o + sheen_lambda(cos_t, alpha));
        double row = 0;
        for (int j = 0; j < steps; ++j) {
            const float phi = float((j + 0.5) * d_phi);
            const Vec3 wm = normalize(wo + Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t));
            row += double(charlie_d(wm, alpha));
        }
        sum += row * double(sin_t) / double(masking);
    }
    return 2.0 * sum * d_theta * d_phi;
}

}  // namespace

float charlie_d(const Vec3& wm, float alpha) {
    const float sin2 = std::max(0.0f, 1.0f - wm.z * wm.z);
    const float inv_alpha = 1.0f / alpha;
    return (2.0f + inv_alpha) * std::pow(sin2, 0.5f * inv_alpha) / (2.0f * kPi);
}

float sheen_lambda(float cos_theta, float alpha) {
    const float c = std::abs(cos_theta);
    // The fit is made for cos < 0.5 and mirrored about 0.5 above it.
    return c < 0.5f ? std::exp(sheen_l(c, alpha))
                    : std::exp(2.0f * sheen_l(0.5f, alpha) - sheen_l(1.0f - c, alpha));
}

float sheen_lobe(const Vec3& wo, const Vec3& wi, float alpha) {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    const Vec3 wm = normalize(wo + wi);
    const float masking = 1.0f + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha);
    return charlie_d(wm, alpha) / (4.0f * wo.z * masking);
}

SheenAlbedoTable::SheenAlbedoTable(int steps) {
    table_.resize(size_t(kRoughnessSteps) * kMuSteps);
    for (int r = 0; r < kRoughnessSteps; ++r) {
        const float alpha = sheen_alpha(float(r) / float(kRoughnessSteps - 1));
        for (int m = 0; m < kMuSteps; ++m) {
            const float x = float(m) / float(kMuSteps - 1);
            table_[size_t(r) * kMuSteps + size_t(m)] = float(integrate_albedo(x * x, alpha, steps));
        }
    }
}

const SheenAlbedoTable& SheenAlbedoTable::get() {
    static const SheenAlbedoTable table(64);
    return table;
}

float SheenAlbedoTable::at(float mu, float roughness) const {
    int i, j;
    float t, s;
    albedo_table_cell(roughness, kRoughnessSteps, &i, &t);
    albedo_table_cell(std::sqrt(std::max(mu, 0.0f)), kMuSteps, &j, &s);
    return albedo_table_lerp([&](int r, int m) { return table_[size_t(r) * kMuSteps + size_t(m)]; }, i, t, j,
                             s);
}

}  // namespace sahara
