#pragma once
/// Directional albedo of the GGX reflection lobe, for the multiple-scattering
/// energy compensation of Kulla and Conty ("Revisiting Physically Based
/// Shading at Imageworks", SIGGRAPH 2017 course). Tabulated once per process
/// by numerical integration (nothing copied), then looked up bilinearly.
#include <algorithm>
#include <vector>

#include "math/vec3.h"

namespace sahara {

/// Cell i and linear weight t of x in [0, 1] over n equally spaced table samples
/// (the albedo tables' lookup: GGX here, sheen in render/sheen.cpp).
inline void albedo_table_cell(float x, int n, int* i, float* t) {
    const float f = std::clamp(x, 0.0f, 1.0f) * float(n - 1);
    *i = std::min(int(f), n - 2);
    *t = f - float(*i);
}

/// The bilinear blend in an albedo table's cell (i, t) x (j, s) from albedo_table_cell:
/// `entry(r, m)` is the table's value at row r, column m.
template <class Entry>
float albedo_table_lerp(Entry entry, int i, float t, int j, float s) {
    const float row0 = (1 - s) * entry(i, j) + s * entry(i, j + 1);
    const float row1 = (1 - s) * entry(i + 1, j) + s * entry(i + 1, j + 1);
    return (1 - t) * row0 + t * row1;
}

/// GGX alpha never goes below this in the glTF material: alpha = roughness^2 = 0
/// would be a delta lobe, and 1e-3 already reflects like a mirror.
inline constexpr float kMinPbrAlpha = 1e-3f;

/// The single-scattering GGX albedo, split so that Schlick's Fresnel
/// F = F0 + (1 - F0) (1 - cos)^5 stays linear in F0:
///   E(mu) F0 + Es(mu) (1 - F0)  with  E = albedo with F = 1,  Es = albedo with F = (1 - cos)^5.
struct GgxAlbedo {
    float e = 1, e_schlick = 0;
};

/// E and Es towards wo (wo.z > 0) by stratified visible-normal sampling, for
/// the isotropic and the anisotropic tables alike: each sample's weight
/// f cos / pdf is G2 / G1(wo) times the Fresnel term. `lambda(w)` is the
/// lobe's Smith Lambda and `sample_vndf(u)` its visible normal for wo.
template <class Lambda, class SampleVndf>
GgxAlbedo integrate_ggx_albedo(const Vec3& wo, Lambda lambda, SampleVndf sample_vndf, int strata) {
    const double lo = lambda(wo);
    double e = 0, es = 0;
    for (int i = 0; i < strata; ++i)
        for (int j = 0; j < strata; ++j) {
            const Vec2 u{(float(i) + 0.5f) / float(strata), (float(j) + 0.5f) / float(strata)};
            const Vec3 wm = sample_vndf(u);
            const Vec3 wi = wm * (2.0f * dot(wo, wm)) - wo;
            if (wi.z <= 0) continue;
            const double w = (1.0 + lo) / (1.0 + lo + double(lambda(wi)));
            const double m = std::clamp(1.0 - double(dot(wo, wm)), 0.0, 1.0);
            e += w;
            es += w * (m * m) * (m * m) * m;
        }
    const double n = double(strata) * double(strata);
    return {float(e / n), float(es / n)};
}

class GgxAlbedoTable {
   public:
    static constexpr int kMuSteps = 64, kRoughnessSteps = 32;

    /// The process-wide table, built on first use (thread-safe).
    static const GgxAlbedoTable& get();

    /// Albedo for outgoing cosine mu in [0, 1] and perceptual roughness in [0, 1].
    GgxAlbedo at(float mu, float roughness) const;
    /// Cosine-weighted hemispherical averages 2 * integral of E(mu) mu dmu of the
    /// same piecewise-linear functions at() interpolates, so the compensation
    /// lobe built from them integrates exactly to what the table says is missing.
    GgxAlbedo average(float roughness) const;

    /// Built by numerical integration with `strata` x `strata` visible-normal samples per entry.
    explicit GgxAlbedoTable(int strata);

   private:
    std::vector<GgxAlbedo> table_;  ///< kRoughnessSteps rows of kMuSteps
    std::vector<GgxAlbedo> avg_;    ///< one per roughness row
};

/// The alpha the glTF material uses for a perceptual roughness.
inline float pbr_alpha(float roughness) {
    const float a = roughness * roughness;
    return a < kMinPbrAlpha ? kMinPbrAlpha : a;
}

}  // namespace sahara
