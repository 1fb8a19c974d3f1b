#pragma once
/// Direct light sampling (next-event estimation): pick an emitter by power,
/// then a direction towards it — point and directional lights exactly,
/// spheres by the solid angle of their visible cap, triangles and boxes by
/// area, the envmap by its luminance. The densities are also evaluated for
/// directions found by BSDF sampling, for multiple importance sampling.
#include <limits>

#include "geometry/hit.h"
#include "scene/scene.h"

namespace sahara {

/// A direction towards a light and what arrives along it.
struct LightSample {
    Vec3 wi;               ///< unit direction from the shading point
    float distance = 0;    ///< to the sampled point (kInfinity: directional, envmap)
    Rgb li{0.0f};          ///< radiance (area, envmap) or irradiance at normal incidence (delta)
    float pdf = 0;         ///< selection probability times solid-angle density (delta: selection only)
    bool delta = false;    ///< point or directional light: no MIS
    uint32_t emitter = 0;  ///< which of Scene::emitters (its shadow cache: shadow_cache)
};

/// The calling thread's shadow cache for emitter or light `index`, for
/// Scene::occluded. Lights whose indices are equal modulo the table's size share an
/// entry, which costs cache hits, never answers.
OcclusionCache& shadow_cache(uint32_t index);

/// Samples one emitter of the scene as seen from p at the given time; false if
/// there is nothing to sample or the sample carries no light.
bool sample_light(const Scene& scene, const Vec3& p, float time, float u_select, Vec2 u, LightSample& ls);

/// Emitter id of the primitive of `hit` (kNoEmitter if it is not light-sampled).
uint32_t emitter_of_hit(const Scene& scene, const Hit& hit);

/// Density (selection probability times solid angle) with which sample_light
/// from p would have produced the point p_light with outward normal n_light
/// on area emitter `emitter`.
float area_light_pdf(const Scene& scene, uint32_t emitter, const Vec3& p, const Vec3& p_light,
                     const Vec3& n_light, float time);

/// Density with which sample_light would have chosen direction `dir` on the envmap.
float envmap_light_pdf(const Scene& scene, const Vec3& dir);

/// Ray for a shadow test from surface point p (geometric normal ng) towards a
/// light sample: robust origin, tmax slightly short of the light.
Ray shadow_ray(const Vec3& p, const Vec3& ng, const LightSample& ls, float time);

/// Power heuristic with beta = 2 (Veach 1997) for two one-sample strategies.
inline float power_heuristic(float pdf_a, float pdf_b) {
    const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    if (a + b <= std::numeric_limits<float>::max()) return a + b > 0 ? a / (a + b) : 0.0f;
    // A square overflowed: densities of 1e19 and more are real (a light seen edge-on
    // from a point on an infinite plane far away), and inf/inf would give NaN.
    // Compare the densities by their ratio instead.
    if (!(pdf_a > 0)) return 0.0f;
    if (!(pdf_b > 0) || pdf_b < pdf_a) {
        const float r = pdf_b > 0 ? pdf_b / pdf_a : 0.0f;
        return 1.0f / (1.0f + r * r);
    }
    if (pdf_a == pdf_b) return 0.5f;  // both infinite
    const float r = pdf_a / pdf_b;
    return r * r / (1.0f + r * r);
}

}  // namespace sahara
