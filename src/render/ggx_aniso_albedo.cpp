#include "render/ggx_aniso_albedo.h"

#include <algorithm>
#include <cmath>

#include "render/ggx.h"

namespace sahara {

namespace {

/// alpha_x of the table's stretch coordinate s in [0, 1]: the perceptual
/// roughness sqrt(alpha_x) goes linearly from sqrt(alpha_y) to 1.
float stretched_alpha(float alpha_y, float s) {
    const float ry = std::sqrt(alpha_y), rx = ry + (1.0f - ry) * s;
    return rx * rx;
}

constexpr float kHalfPi = 0.5f * kPi;

/// Table coordinates in [0, 1], denser where the albedo changes fastest: the
/// cosine mu at equal steps of sqrt(mu) (grazing angles), the azimuth phi at
/// equal steps of 1 - sqrt(1 - phi / (pi/2)) (near the smoother axis, where the
/// roughness seen along wo grows fastest with phi).
float mu_coordinate(float mu) { return std::sqrt(std::max(mu, 0.0f)); }
float mu_of_coordinate(float x) { return x * x; }
float phi_coordinate(float phi) { return 1.0f - std::sqrt(std::max(0.0f, 1.0f - phi / kHalfPi)); }
float phi_of_coordinate(float y) { return kHalfPi * (1.0f - (1.0f - y) * (1.0f - y)); }

/// Integral over [0, 1] of hat_k(x) density(x) dx for the n hat functions of
/// linear interpolation between equally spaced samples: the weights that
/// average the interpolated function. Three-point Gauss-Legendre per interval
/// is exact for the polynomial densities used here.
template <class Density>
std::vector<double> hat_weights(int n, Density density) {
    std::vector<double> w(size_t(n), 0.0);
    const double h = 1.0 / double(n - 1);
    const double nodes[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, weights[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
    for (int k = 0; k + 1 < n; ++k)
        for (int g = 0; g < 3; ++g) {
            const double t = 0.5 * (1.0 + nodes[g]), x = (double(k) + t) * h;
            const double dw = weights[g] * 0.5 * h * density(x);
            w[size_t(k)] += (1.0 - t) * dw;
            w[size_t(k) + 1] += t * dw;
        }
    return w;
}

}  // namespace

GgxAnisoAlbedoTable::GgxAnisoAlbedoTable(int strata) {
    table_.resize(size_t(kRoughnessSteps) * kStretchSteps * kMuSteps * kPhiSteps);
    avg_.resize(size_t(kRoughnessSteps) * kStretchSteps);
    // Cosine-weighted hemispherical mean: 2 mu dmu = 4 x^3 dx over the cosine's
    // coordinate, dphi / (pi/2) = 2 (1 - y) dy over the azimuth's (a quarter turn
    // holds every azimuth by the lobe's mirror symmetries).
    const std::vector<double> mu_w = hat_weights(kMuSteps, [](double x) { return 4 * x * x * x; });
    const std::vector<double> phi_w = hat_weights(kPhiSteps, [](double y) { return 2 * (1 - y); });
    for (int r = 0; r < kRoughnessSteps; ++r)
        for (int s = 0; s < kStretchSteps; ++s) {
            const float alpha_y = pbr_alpha(float(r) / float(kRoughnessSteps - 1));
            const float alpha_x = stretched_alpha(alpha_y, float(s) / float(kStretchSteps - 1));
            double e_avg = 0, es_avg = 0;
            for (int m = 0; m < kMuSteps; ++m) {
                const float mu = std::max(mu_of_coordinate(float(m) / float(kMuSteps - 1)), 1e-4f);
                const float sin_o = std::sqrt(std::max(0.0f, 1.0f - mu * mu));
                for (int p = 0; p < kPhiSteps; ++p) {
                    const float phi = phi_of_coordinate(float(p) / float(kPhiSteps - 1));
                    const Vec3 wo(sin_o * std::cos(phi), sin_o * std::sin(phi), mu);
                    const GgxAlbedo a = integrate_ggx_albedo(
                        wo, [&](const Vec3& w) { return ggx_lambda(w, alpha_x, alpha_y); },
                        [&](const Vec2& u) { return sample_ggx_vndf(wo, alpha_x, alpha_y, u); }, strata);
                    table_[index(r, s, m, p)] = a;
                    const double w = mu_w[size_t(m)] * phi_w[size_t(p)];
                    e_avg += w * double(a.e);
                    es_avg += w * double(a.e_schlick);
                }
            }
            avg_[size_t(r) * kStretchSteps + size_t(s)] = {float(e_avg), float(es_avg)};
        }
}

const GgxAnisoAlbedoTable& GgxAnisoAlbedoTable::get() {
    static const GgxAnisoAlbedoTable table(7);
    return table;
}

void GgxAnisoAlbedoTable::material_cell(float alpha_x, float alpha_y, Cell* c) {
    const float ry = std::sqrt(alpha_y);
    const float stretch = ry < 1.0f ? std::max(0.0f, (std::sqrt(alpha_x) - ry) / (1.0f - ry)) : 0.0f;
    albedo_table_cell(ry, kRoughnessSteps, &c->i[0], &c->t[0]);
    albedo_table_cell(stretch, kStretchSteps, &c->i[1], &c->t[1]);
}

GgxAlbedo GgxAnisoAlbedoTable::at(const Vec3& wo, float alpha_x, float alpha_y) const {
    // The table holds alpha_x >= alpha_y; the other case is the same lobe turned a quarter.
    float x = std::abs(wo.x), y = std::abs(wo.y);
    if (alpha_x < alpha_y) {
        std::swap(alpha_x, alpha_y);
        std::swap(x, y);
    }
    Cell c;
    material_cell(alpha_x, alpha_y, &c);
    albedo_table_cell(mu_coordinate(wo.z), kMuSteps, &c.i[2], &c.t[2]);
    albedo_table_cell(x > 0 || y > 0 ? phi_coordinate(std::atan2(y, x)) : 0.0f, kPhiSteps, &c.i[3], &c.t[3]);
    GgxAlbedo out{0, 0};
    for (int corner = 0; corner < 16; ++corner) {
        float w = 1;
        int k[4];
        for (int d = 0; d < 4; ++d) {
            const bool upper = (corner >> d) & 1;
            k[d] = c.i[d] + (upper ? 1 : 0);
            w *= upper ? c.t[d] : 1.0f - c.t[d];
        }
        const GgxAlbedo& a = table_[index(k[0], k[1], k[2], k[3])];
        out.e += w * a.e;
        out.e_schlick += w * a.e_schlick;
    }
    return out;
}

GgxAlbedo GgxAnisoAlbedoTable::average(float alpha_x, float alpha_y) const {
    if (alpha_x < alpha_y) std::swap(alpha_x, alpha_y);
    Cell c;
    material_cell(alpha_x, alpha_y, &c);
    GgxAlbedo out{0, 0};
    for (int corner = 0; corner < 4; ++corner) {
        const int r = c.i[0] + (corner & 1), s = c.i[1] + (corner >> 1);
        const float w = ((corner & 1) ? c.t[0] : 1.0f - c.t[0]) * ((corner >> 1) ? c.t[1] : 1.0f - c.t[1]);
        const GgxAlbedo& a = avg_[size_t(r) * kStretchSteps + size_t(s)];
        out.e += w * a.e;
        out.e_schlick += w * a.e_schlick;
    }
    return out;
}

}  // namespace sahara
