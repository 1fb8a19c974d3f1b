#pragma once
/// Clearcoat (KHR_materials_clearcoat) and sheen (KHR_materials_sheen) over
/// the glTF material's base (bsdf_pbr.h), in the extensions' order: sheen on
/// the base, the coat on top of both,
///   f = coat + (1 - c E_coat(mu_o)) (sheen + (1 - max(sheen colour) E_sheen(mu_o)) base).
///
/// The coat is a GGX reflection (its own roughness and, optionally, normal)
/// weighted by c F(mu_o), F Schlick's Fresnel of an ior 1.5 interface at the
/// coat normal, as the extension defines it; E_coat = F(mu_o) E(mu_o) is the
/// coat's directional albedo, E from the GGX albedo table. The extension's
/// own layering scales the base by 1 - c F(mu_o), which loses the light a
/// rough coat's single scattering does not reflect; scaling by what the coat
/// really reflects keeps a white material white. The sheen lobe is the Charlie
/// lobe of sheen.h times the sheen colour, divided by its albedo where that
/// exceeds 1 (grazing views of the smoothest sheens), and the base is scaled
/// by the sheen's albedo as the extension specifies. Both scalings depend on
/// wo only, as in the extension: light the layers do not reflect reaches the
/// base, so nothing is created or lost for a white base.
///
/// Sampling picks the coat (visible normals), the sheen (uniform hemisphere)
/// or the base by their albedos at wo; eval returns the density of that mixture.
/// Local frame of the base (+z its shading normal), wo.z > 0.
#include "render/bsdf.h"

namespace sahara {

/// The coat's ior, as KHR_materials_clearcoat fixes it.
inline constexpr float kCoatIor = 1.5f;

/// The probabilities of the coat, the sheen and the base at wo, and the base's scale.
struct LayerWeights {
    float coat = 0, sheen = 0, base = 0;
    float base_scale = 1;  ///< (1 - c E_coat) (1 - max(sheen) E_sheen)
    float sheen_scale =
        0;  ///< what multiplies the sheen colour x sheen lobe: (1 - c E_coat) / max(1, E_sheen)
    float coat_fresnel = 0;  ///< c F(mu_o) at the coat normal
    float sheen_albedo = 0;  ///< what the sheen lobe of colour 1 reflects in all, under the coat
};

LayerWeights pbr_layer_weights(const Bsdf& b, const Vec3& wo);

/// clearcoat x F(cos_coat): the part of the light the coat reflects at cos_coat to
/// its normal (Schlick, ior 1.5), which is also the part of the base's emission it
/// keeps from leaving that way.
float coat_fresnel(float clearcoat, float cos_coat);

/// eval_pbr of a material with b.layers.on: f cos and the mixture's density.
Rgb eval_pbr_layered(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf);

/// A direction from the coat, the sheen or the base, picked by u_lobe; false if none.
bool sample_pbr_layered_direction(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, Vec3* wi);

}  // namespace sahara
