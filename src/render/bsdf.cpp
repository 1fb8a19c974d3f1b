#include "render/bsdf.h"

#include <cmath>

#include "render/bsdf_pbr.h"
#include "scene/texture.h"

namespace sahara {

float fresnel_dielectric(float cos_i, float eta) {
    cos_i = std::clamp(cos_i, 0.0f, 1.0f);
    const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    const float cos_t = std::sqrt(1.0f - sin2_t);
    const float r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const float r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

Rgb fresnel_schlick(const Rgb& f0, float cos_i) {
    const float m = std::clamp(1.0f - cos_i, 0.0f, 1.0f);
    const float m5 = (m * m) * (m * m) * m;
    return f0 + (Rgb(1.0f) - f0) * m5;
}

Rgb fresnel_schlick(const Rgb& f0, float f90, float cos_i) {
    const float m = std::clamp(1.0f - cos_i, 0.0f, 1.0f);
    const float m5 = (m * m) * (m * m) * m;
    return f0 + (Rgb(f90) - f0) * m5;
}

bool refract(const Vec3& wo, const Vec3& n, float eta, Vec3* wt) {
    const float cos_i = dot(wo, n);
    const float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return false;
    const float cos_t = std::sqrt(1.0f - sin2_t);
    *wt = -wo / eta + n * (cos_i / eta - cos_t);
    return true;
}

namespace {

/// GGX reflection with Smith's height-correlated G2 and Schlick Fresnel on F0.
Rgb eval_ggx(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    *pdf = 0;
    if (wo.z <= 0 || wi.z <= 0) return Rgb(0.0f);
    const Vec3 wm = normalize(wo + wi);
    const float d = ggx_d(wm, b.alpha);
    const float lo = ggx_lambda(wo, b.alpha), li = ggx_lambda(wi, b.alpha);
    const float g1 = 1.0f / (1.0f + lo), g2 = 1.0f / (1.0f + lo + li);
    const float wo_wm = dot(wo, wm);
    if (wo_wm <= 0) return Rgb(0.0f);
    // Visible-normal density D_wo(wm) = G1(wo) max(0, wo.wm) D(wm) / cos_o, and
    // the reflection Jacobian 1 / (4 wo.wm).
    *pdf = g1 * d / (4.0f * wo.z);
    return fresnel_schlick(b.albedo, wo_wm) * (d * g2 / (4.0f * wo.z));
}

bool sample_dielectric(const Bsdf& b, const Vec3& wo, float u_lobe, BsdfSample& s) {
    const float r = fresnel_dielectric(wo.z, b.eta);
    s.delta = true;
    s.pdf = 1;
    if (u_lobe < r) {
        s.wi = Vec3(-wo.x, -wo.y, wo.z);
        s.weight = Rgb(1.0f);  // (R / cos) * cos / R
        return true;
    }
    Vec3 wt;
    if (!refract(wo, Vec3(0, 0, 1), b.eta, &wt)) return false;  // unreachable: r == 1 under TIR
    s.wi = wt;
    s.transmit = true;
    // Radiance is compressed by (n_t / n_i)^2 when it crosses into the denser medium.
    const float inv_eta2 = 1.0f / (b.eta * b.eta);
    s.weight = Rgb(inv_eta2);
    s.eta_scale = b.eta * b.eta;
    return true;
}

}  // namespace

Bsdf make_bsdf(const MaterialDesc& m, const SurfaceInteraction& si, const std::vector<TextureDesc>& textures,
               float wavelength_nm) {
    Bsdf b;
    b.frame = Frame(si.ns);
    b.ng = si.ng;
    switch (m.type) {
        case MaterialType::pbr:
            make_pbr_bsdf(b, m, si, textures, wavelength_nm);
            break;
        case MaterialType::lambertian:
            b.kind = BsdfKind::lambertian;
            b.albedo = material_albedo(m, si, textures);
            break;
        case MaterialType::metal:
            b.albedo = material_albedo(m, si, textures);
            b.alpha = m.roughness * m.roughness;  // perceptual roughness, as in glTF
            b.kind = b.alpha < kMinGgxAlpha ? BsdfKind::mirror : BsdfKind::ggx;
            break;
        case MaterialType::dielectric:
            b.kind = BsdfKind::dielectric;
            b.eta = si.front_face ? m.ior : 1.0f / m.ior;
            break;
        case MaterialType::emissive:
        case MaterialType::unlit:  // the integrators show its colour without scattering
            b.kind = BsdfKind::none;
            break;
    }
    return b;
}

Rgb eval_bsdf(const Bsdf& b, const Vec3& wo_w, const Vec3& wi_w, float* pdf) {
    *pdf = 0;
    if (b.kind == BsdfKind::pbr) {
        // Reflection or transmission as the true surface says; the shading frame must agree.
        const Vec3 wi = b.frame.to_local(wi_w);
        if ((dot(wi_w, b.ng) > 0) != (wi.z > 0)) return Rgb(0.0f);
        return eval_pbr(b, b.frame.to_local(wo_w), wi, pdf);
    }
    // Reflection only: wi must leave on the same side of the true surface as wo.
    if (dot(wi_w, b.ng) <= 0) return Rgb(0.0f);
    const Vec3 wi = b.frame.to_local(wi_w);
    switch (b.kind) {
        case BsdfKind::lambertian:
            if (wi.z <= 0) return Rgb(0.0f);
            *pdf = wi.z * kInvPi;
            return b.albedo * (wi.z * kInvPi);
        case BsdfKind::ggx:
            return eval_ggx(b, b.frame.to_local(wo_w), wi, pdf);
        default:
            return Rgb(0.0f);
    }
}

bool sample_bsdf(const Bsdf& b, const Vec3& wo_w, Vec2 u, float u_lobe, BsdfSample& s) {
    const Vec3 wo = b.frame.to_local(wo_w);
    switch (b.kind) {
        case BsdfKind::lambertian: {
            const Vec3 wi = sample_cosine_hemisphere(u);
            s.wi = b.frame.to_world(wi);
            s.pdf = wi.z * kInvPi;
            s.weight = b.albedo;
            s.delta = false;
            break;
        }
        case BsdfKind::mirror:
            if (wo.z <= 0) return false;
            s.wi = b.frame.to_world(Vec3(-wo.x, -wo.y, wo.z));
            s.pdf = 1;
            s.weight = fresnel_schlick(b.albedo, wo.z);
            s.delta = true;
            break;
        case BsdfKind::ggx: {
            if (wo.z <= 0) return false;
            const Vec3 wm = sample_ggx_vndf(wo, b.alpha, u);
            const Vec3 wi = reflect(wo, wm);
            if (wi.z <= 0) return false;
            s.wi = b.frame.to_world(wi);
            const float lo = ggx_lambda(wo, b.alpha), li = ggx_lambda(wi, b.alpha);
            s.pdf = ggx_d(wm, b.alpha) / ((1.0f + lo) * 4.0f * wo.z);
            // f cos / pdf = F G2 / G1(wo) with visible-normal sampling.
            s.weight = fresnel_schlick(b.albedo, dot(wo, wm)) * ((1.0f + lo) / (1.0f + lo + li));
            s.delta = false;
            break;
        }
        case BsdfKind::pbr:
            if (!sample_pbr(b, wo, u, u_lobe, s)) return false;
            s.wi = b.frame.to_world(s.wi);
            return s.transmit ? dot(s.wi, b.ng) < 0 : dot(s.wi, b.ng) > 0;
        case BsdfKind::dielectric:
            if (!sample_dielectric(b, wo, u_lobe, s)) return false;
            s.wi = b.frame.to_world(s.wi);
            // A shading normal can send the sample to the wrong side of the true surface.
            return s.transmit ? dot(s.wi, b.ng) < 0 : dot(s.wi, b.ng) > 0;
        case BsdfKind::none:
            return false;
    }
    s.transmit = false;
    return dot(s.wi, b.ng) > 0;
}

}  // namespace sahara
