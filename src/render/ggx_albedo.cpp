#include "render/ggx_albedo.h"

#include <algorithm>
#include <cmath>

#include "render/ggx.h"

namespace sahara {

namespace {

/// E and Es at one (mu, alpha).
GgxAlbedo integrate_albedo(float mu, float alpha, int strata) {
    mu = std::max(mu, 1e-4f);
    const Vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
    return integrate_ggx_albedo(
        wo, [&](const Vec3& w) { return ggx_lambda(w, alpha); },
        [&](const Vec2& u) { return sample_ggx_vndf(wo, alpha, u); }, strata);
}

/// 2 * integral over [0, 1] of f(mu) mu dmu for f linear between equally spaced samples.
double cosine_average(const std::vector<double>& f) {
    const double h = 1.0 / double(f.size() - 1);
    double sum = 0;
    for (size_t k = 0; k + 1 < f.size(); ++k) {
        const double a = double(k) * h, b = a + h;
        const double slope = (f[k + 1] - f[k]) / h;
        // integral of (f_k + slope (mu - a)) mu over [a, b]
        sum += f[k] * (b * b - a * a) / 2 + slope * ((b * b * b - a * a * a) / 3 - a * (b * b - a * a) / 2);
    }
    return 2 * sum;
}

}  // namespace

GgxAlbedoTable::GgxAlbedoTable(int strata) {
    table_.resize(size_t(kRoughnessSteps) * kMuSteps);
    avg_.resize(kRoughnessSteps);
    for (int r = 0; r < kRoughnessSteps; ++r) {
        const float alpha = pbr_alpha(float(r) / float(kRoughnessSteps - 1));
        std::vector<double> e(kMuSteps), es(kMuSteps);
        for (int m = 0; m < kMuSteps; ++m) {
            const GgxAlbedo a = integrate_albedo(float(m) / float(kMuSteps - 1), alpha, strata);
            table_[size_t(r) * kMuSteps + size_t(m)] = a;
            e[size_t(m)] = a.e;
            es[size_t(m)] = a.e_schlick;
        }
        avg_[size_t(r)] = {float(cosine_average(e)), float(cosine_average(es))};
    }
}

const GgxAlbedoTable& GgxAlbedoTable::get() {
    static const GgxAlbedoTable table(48);
    return table;
}

GgxAlbedo GgxAlbedoTable::at(float mu, float roughness) const {
    int i, j;
    float t, s;
    albedo_table_cell(roughness, kRoughnessSteps, &i, &t);
    albedo_table_cell(mu, kMuSteps, &j, &s);
    auto lerp2 = [&](float GgxAlbedo::*f) {
        return albedo_table_lerp([&](int r, int m) { return table_[size_t(r) * kMuSteps + size_t(m)].*f; }, i,
                                 t, j, s);
    };
    return {lerp2(&GgxAlbedo::e), lerp2(&GgxAlbedo::e_schlick)};
}

GgxAlbedo GgxAlbedoTable::average(float roughness) const {
    int i;
    float t;
    albedo_table_cell(roughness, kRoughnessSteps, &i, &t);
    const GgxAlbedo a = avg_[size_t(i)], b = avg_[size_t(i) + 1];
    return {(1 - t) * a.e + t * b.e, (1 - t) * a.e_schlick + t * b.e_schlick};
}

}  // namespace sahara
