#pragma once
/// The sheen lobe of KHR_materials_sheen: the "Charlie" distribution of
/// Estevez and Kulla ("Production Friendly Microfacet Sheen BRDF", SIGGRAPH
/// 2017) with the masking term the extension specifies (their fitted Lambda),
/// and a table of its directional albedo for the albedo-scaling layering.
/// Local frame, normal +z.
#include <vector>

#include "math/vec3.h"

namespace sahara {

/// Sheen alpha never goes below this: alpha = roughness^2 = 0 would put all of
/// the lobe on the horizon, where nothing can integrate it.
inline constexpr float kMinSheenAlpha = 0.01f;

/// The alpha the sheen lobe uses for a perceptual sheen roughness.
inline float sheen_alpha(float roughness) {
    const float a = roughness * roughness;
    return a < kMinSheenAlpha ? kMinSheenAlpha : a;
}

/// Charlie distribution D(wm) = (2 + 1/alpha) sin(theta_m)^(1/alpha) / (2 pi).
float charlie_d(const Vec3& wm, float alpha);

/// The extension's sheen masking Lambda(cos theta).
float sheen_lambda(float cos_theta, float alpha);

/// f cos of the sheen lobe with sheen colour 1:
/// D(wm) / (4 cos_o (1 + Lambda(cos_o) + Lambda(cos_i))); zero unless both are above.
float sheen_lobe(const Vec3& wo, const Vec3& wi, float alpha);

/// Directional albedo E(mu) of sheen_lobe, tabulated once per process by
/// numerical integration over the hemisphere, then looked up bilinearly. The
/// rows are spaced evenly in sqrt(mu): E peaks steeply near mu = 0.01.
class SheenAlbedoTable {
   public:
    static constexpr int kMuSteps = 32, kRoughnessSteps = 32;

    /// The process-wide table, built on first use (thread-safe).
    static const SheenAlbedoTable& get();

    /// Albedo for outgoing cosine mu in [0, 1] and perceptual sheen roughness in [0, 1].
    float at(float mu, float roughness) const;

    /// Built with a `steps` x `steps` midpoint grid over (theta_i, phi_i) per entry.
    explicit SheenAlbedoTable(int steps);

   private:
    std::vector<float> table_;  ///< kRoughnessSteps rows of kMuSteps
};

}  // namespace sahara
