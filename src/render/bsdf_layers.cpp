#include "render/bsdf_layers.h"

#include <algorithm>
#include <cmath>

#include "render/bsdf_pbr.h"
#include "render/ggx_albedo.h"
#include "render/sheen.h"

namespace sahara {

namespace {

/// Schlick F0 of the coat: an ior 1.5 interface, ((1.5 - 1) / (1.5 + 1))^2.
constexpr float kCoatF0 = 0.04f;

float mean(const Rgb& c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

/// Directions in the coat's frame; the coat frame is built only when the coat
/// has its own normal, which keeps the common case free of the rotation.
struct CoatFrame {
    explicit CoatFrame(const BsdfLayers& l) : own(l.coat_frame), frame(l.coat_normal) {}
    Vec3 to_coat(const Vec3& w) const { return own ? frame.to_local(w) : w; }
    Vec3 to_base(const Vec3& w) const { return own ? frame.to_world(w) : w; }
    bool own;
    Frame frame;
};

/// Uniform directions over the upper hemisphere, density 1 / (2 pi): the
/// sheen lobe is widest at grazing angles, where a cosine density has none.
Vec3 sample_uniform_hemisphere(Vec2 u) {
    const float z = u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

constexpr float kUniformHemispherePdf = 0.5f * kInvPi;

}  // namespace

float coat_fresnel(float clearcoat, float cos_coat) {
    return clearcoat * fresnel_schlick(Rgb(kCoatF0), cos_coat).x;
}

LayerWeights pbr_layer_weights(const Bsdf& b, const Vec3& wo) {
    const BsdfLayers& l = b.layers;
    LayerWeights w;
    float coat_albedo = 0;
    if (l.clearcoat > 0) {
        const Vec3 wo_c = CoatFrame(l).to_coat(wo);
        if (wo_c.z > 0) {
            w.coat_fresnel = coat_fresnel(l.clearcoat, wo_c.z);
            coat_albedo = w.coat_fresnel * GgxAlbedoTable::get().at(wo_c.z, l.coat_roughness).e;
        }
    }
    const float through_coat = 1.0f - coat_albedo;
    float sheen_albedo = 0;  // of the lobe with colour 1, at most 1
    if (max_component(l.sheen) > 0) {
        const float e = SheenAlbedoTable::get().at(wo.z, l.sheen_roughness);
        sheen_albedo = std::min(e, 1.0f);
        w.sheen_scale = through_coat / std::max(e, 1.0f);
        w.sheen_albedo = through_coat * sheen_albedo;
    }
    w.base_scale = through_coat * (1.0f - max_component(l.sheen) * sheen_albedo);
    const float coat = coat_albedo, sheen = mean(l.sheen) * w.sheen_albedo;
    const float base = w.base_scale * pbr_lobe_weights(b, wo).total;
    const float sum = coat + sheen + base;
    if (!(sum > 0)) return w;
    w.coat = coat / sum;
    w.sheen = sheen / sum;
    w.base = base / sum;
    return w;
}

Rgb eval_pbr_layered(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    *pdf = 0;
    if (wo.z <= 0 || wi.z == 0) return Rgb(0.0f);
    const BsdfLayers& l = b.layers;
    const LayerWeights w = pbr_layer_weights(b, wo);
    float base_pdf = 0;
    Rgb f = eval_pbr_base(b, wo, wi, &base_pdf) * w.base_scale;
    float p = w.base * base_pdf;
    if (wi.z > 0 && w.coat_fresnel > 0) {
        const CoatFrame coat(l);
        const Vec3 wo_c = coat.to_coat(wo), wi_c = coat.to_coat(wi);
        if (wi_c.z > 0) {
            const Vec3 wm = normalize(wo_c + wi_c);
            const float g2 = 1.0f / (1.0f + ggx_lambda(wo_c, l.coat_alpha) + ggx_lambda(wi_c, l.coat_alpha));
            f += Rgb(w.coat_fresnel * ggx_d(wm, l.coat_alpha) * g2 / (4.0f * wo_c.z));
            p += w.coat * ggx_reflection_pdf(wo_c, wi_c, l.coat_alpha);
        }
    }
    if (wi.z > 0 && w.sheen_scale > 0) {
        f += l.sheen * (w.sheen_scale * sheen_lobe(wo, wi, l.sheen_alpha));
        p += w.sheen * kUniformHemispherePdf;
    }
    *pdf = p;
    return f;
}

bool sample_pbr_layered_direction(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, Vec3* wi) {
    const LayerWeights w = pbr_layer_weights(b, wo);
    if (u_lobe < w.coat) {
        const CoatFrame coat(b.layers);
        const Vec3 wo_c = coat.to_coat(wo);
        const Vec3 wi_c = reflect(wo_c, sample_ggx_vndf(wo_c, b.layers.coat_alpha, u));
        if (wi_c.z <= 0) return false;
        *wi = coat.to_base(wi_c);
        return wi->z > 0;  // a coat tilted by its normal map can send it below the base
    }
    if (u_lobe < w.coat + w.sheen) {
        *wi = sample_uniform_hemisphere(u);
        return true;
    }
    if (!(w.base > 0)) return false;
    const float u_base = std::min((u_lobe - w.coat - w.sheen) / w.base, 0x1.fffffep-1f);
    return sample_pbr_base_direction(b, wo, u, u_base, wi);
}

}  // namespace sahara
