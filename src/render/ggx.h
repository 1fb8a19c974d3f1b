#pragma once
/// The GGX (Trowbridge-Reitz) microfacet distribution in a local frame whose
/// normal is +z: density, Smith's Lambda, visible-normal sampling and its
/// density. Shared by the metal BSDF and the glTF material (bsdf_pbr.h).
///
/// The anisotropic forms (two alphas: alpha_x along local x, alpha_y along
/// local y) serve KHR_materials_anisotropy; they are separate functions so that
/// isotropic materials keep their exact arithmetic and pay nothing for them.
#include <algorithm>
#include <cmath>

#include "math/sampling.h"
#include "math/vec3.h"

namespace sahara {

/// Microfacet density D(wm) of the local half vector wm.
inline float ggx_d(const Vec3& wm, float alpha) {
    const float cos2 = wm.z * wm.z;
    if (cos2 <= 0.0f) return 0.0f;
    const float sin2 = std::max(0.0f, 1.0f - cos2);
    const float a2 = alpha * alpha;
    const float denom = cos2 * a2 + sin2;  // = cos^2 * a2 * (1 + tan^2 / a2)
    return a2 / (kPi * denom * denom);
}

/// Smith's Lambda(w); G1 = 1 / (1 + Lambda), height-correlated G2 = 1 / (1 + Lo + Li).
inline float ggx_lambda(const Vec3& w, float alpha) {
    const float cos2 = w.z * w.z;
    if (cos2 <= 0.0f) return 0.0f;
    const float tan2 = std::max(0.0f, 1.0f - cos2) / cos2;
    return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

/// Visible-normal sampling: Heitz, "Sampling the GGX Distribution of Visible
/// Normals" (JCGT 2018). Stretch wo (wo.z > 0) by (alpha_x, alpha_y, 1) to the
/// unit-roughness configuration, sample the projected hemisphere, unstretch.
inline Vec3 sample_ggx_vndf(const Vec3& wo, float alpha_x, float alpha_y, Vec2 u) {
    const Vec3 vh = normalize(Vec3(alpha_x * wo.x, alpha_y * wo.y, wo.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const Vec3 t1 = lensq > 0 ? Vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : Vec3(1, 0, 0);
    const Vec3 t2 = cross(vh, t1);
    const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    const float p1 = r * std::cos(phi);
    const float s = 0.5f * (1.0f + vh.z);
    const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
    const Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2));
    return normalize(Vec3(alpha_x * nh.x, alpha_y * nh.y, std::max(1e-7f, nh.z)));
}

/// Isotropic visible-normal sampling: the same arithmetic with alpha_x = alpha_y.
inline Vec3 sample_ggx_vndf(const Vec3& wo, float alpha, Vec2 u) {
    return sample_ggx_vndf(wo, alpha, alpha, u);
}

/// Density of sample_ggx_vndf's wm: G1(wo) max(0, wo.wm) D(wm) / wo.z.
inline float ggx_vndf_pdf(const Vec3& wo, const Vec3& wm, float alpha) {
    const float wo_wm = dot(wo, wm);
    if (wo.z <= 0 || wo_wm <= 0) return 0.0f;
    return ggx_d(wm, alpha) * wo_wm / ((1.0f + ggx_lambda(wo, alpha)) * wo.z);
}

/// Density of the direction reflect(wo, wm) when wm comes from sample_ggx_vndf:
/// the visible-normal density times the reflection Jacobian 1 / (4 wo.wm).
inline float ggx_reflection_pdf(const Vec3& wo, const Vec3& wi, float alpha) {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    const Vec3 wm = normalize(wo + wi);
    if (dot(wo, wm) <= 0) return 0.0f;
    return ggx_d(wm, alpha) / ((1.0f + ggx_lambda(wo, alpha)) * 4.0f * wo.z);
}

/// Anisotropic D(wm) = 1 / (pi ax ay (x^2/ax^2 + y^2/ay^2 + z^2)^2).
inline float ggx_d(const Vec3& wm, float alpha_x, float alpha_y) {
    if (wm.z * wm.z <= 0.0f) return 0.0f;
    const float x = wm.x / alpha_x, y = wm.y / alpha_y;
    const float denom = x * x + y * y + wm.z * wm.z;
    return 1.0f / (kPi * alpha_x * alpha_y * denom * denom);
}

/// Anisotropic Lambda(w): the isotropic form with the roughness projected on w's azimuth.
inline float ggx_lambda(const Vec3& w, float alpha_x, float alpha_y) {
    const float cos2 = w.z * w.z;
    if (cos2 <= 0.0f) return 0.0f;
    const float t2 = (alpha_x * alpha_x * w.x * w.x + alpha_y * alpha_y * w.y * w.y) / cos2;
    return 0.5f * (std::sqrt(1.0f + t2) - 1.0f);
}

/// Density of the anisotropic sample_ggx_vndf's wm.
inline float ggx_vndf_pdf(const Vec3& wo, const Vec3& wm, float alpha_x, float alpha_y) {
    const float wo_wm = dot(wo, wm);
    if (wo.z <= 0 || wo_wm <= 0) return 0.0f;
    return ggx_d(wm, alpha_x, alpha_y) * wo_wm / ((1.0f + ggx_lambda(wo, alpha_x, alpha_y)) * wo.z);
}

/// Density of reflect(wo, wm) for the anisotropic sample_ggx_vndf.
inline float ggx_reflection_pdf(const Vec3& wo, const Vec3& wi, float alpha_x, float alpha_y) {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    const Vec3 wm = normalize(wo + wi);
    if (dot(wo, wm) <= 0) return 0.0f;
    return ggx_d(wm, alpha_x, alpha_y) / ((1.0f + ggx_lambda(wo, alpha_x, alpha_y)) * 4.0f * wo.z);
}

}  // namespace sahara
