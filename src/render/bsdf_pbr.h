#pragma once
/// The glTF 2.0 metallic-roughness BRDF (the specification's appendix "BRDF
/// implementation"): a dielectric GGX layer (Schlick Fresnel, F0 from the ior)
/// over a Lambertian base, mixed by `metallic` with a GGX conductor whose F0 is
/// the base colour; alpha = roughness^2, Smith height-correlated G2.
///
/// Beyond the specification, energy lost by the single-scattering microfacet
/// model is restored (Kulla and Conty 2017): a compensation lobe
///   f_ms = F_ms (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)),
///   F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),
/// and the Lambertian base is scaled by (1 - Ed(mu_o)) (1 - Ed(mu_i)) / (1 - Ed_avg),
/// Ed being the dielectric layer's albedo, so that light the layer does not
/// reflect reaches the base and the whole stays reciprocal. A white material
/// then reflects everything at any roughness, metallic or not.
///
/// KHR_materials_iridescence replaces, in proportion to its weight, the
/// specular lobe's Fresnel by a thin film's (render/thin_film.h); the
/// dielectric layer's albedo, which scales the base, is then taken at an F0
/// that bounds the film's reflectance, and the film's Fresnel is capped by
/// Schlick's curve from that F0, so the layering still conserves energy.
///
/// Transmission (KHR_materials_transmission) replaces that fraction of the
/// base by a rough dielectric interface (Walter et al. 2007) refracting with
/// the material's ior, as `dielectric` does for a closed volume.
///
/// Diffuse transmission (KHR_materials_diffuse_transmission) replaces that
/// share of what is left of the Lambertian base by a Lambertian lobe on the far
/// side, of its own colour, scaled like the base by what the dielectric layer
/// leaves on both sides: (1 - Ed(mu_o)) (1 - Ed(|mu_i|)) / (1 - Ed_avg).
/// It does not bend light, so it behaves alike on thin walls and volumes.
///
/// All directions here are local (shading normal +z); wo.z > 0 is required.
#include "render/bsdf.h"

namespace sahara {

/// The glTF material's BSDF at `si`: base colour (factor x texture x vertex
/// colour), metallic-roughness texture (G roughness, B metallic), transmission
/// texture (R), normal map; each texture reads its own UV set. With a
/// wavelength (nm, > 0) a dispersive volume takes its ior there (render/dispersion.h).
void make_pbr_bsdf(Bsdf& b, const MaterialDesc& m, const SurfaceInteraction& si,
                   const std::vector<TextureDesc>& textures, float wavelength_nm = 0.0f);

/// Radiance emitted (factor x texture x strength, from either side) towards wo,
/// any length, away from the surface. A clearcoat over the emission lets
/// 1 - clearcoat F(|n_coat . wo|) of it through, as KHR_materials_clearcoat says;
/// a sheen keeps all of it (KHR_materials_sheen layers a BRDF and says nothing of
/// emission). Every integrator and light sampling read the emission here, so a
/// light seen and a light sampled agree.
Rgb pbr_emission(const MaterialDesc& m, const SurfaceInteraction& si,
                 const std::vector<TextureDesc>& textures, const Vec3& wo);

/// The specular lobe's Fresnel at cos_theta to the microfacet normal:
/// Schlick's, the dielectric's and the metal's mixed by metallic, with the
/// thin film where KHR_materials_iridescence puts one (render/thin_film.h).
Rgb pbr_fresnel(const Bsdf& b, float cos_theta);

/// The lobes' weights at one wo: the probabilities sample_pbr uses.
struct PbrLobeWeights {
    float specular = 0;          ///< single-scattering GGX reflection (visible-normal sampled)
    float cosine = 0;            ///< diffuse base and multiple-scattering lobe (cosine sampled)
    float transmit = 0;          ///< rough refraction
    float diffuse_transmit = 0;  ///< Lambertian transmission (KHR_materials_diffuse_transmission)
    float total = 0;             ///< the lobes before normalisation: the base's estimated albedo at wo
};

PbrLobeWeights pbr_lobe_weights(const Bsdf& b, const Vec3& wo);

/// f(wo, wi) |cos_i| and the density sample_pbr gives wi (either hemisphere).
Rgb eval_pbr(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf);

/// Picks a lobe by u_lobe, a direction by u; s.wi is local.
bool sample_pbr(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, BsdfSample& s);

/// The base material alone, without clearcoat and sheen (what eval_pbr is
/// when b.layers.on is false); render/bsdf_layers.cpp layers over these.
Rgb eval_pbr_base(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf);
/// A direction from the base's lobes (wo.z > 0); false if the lobe gives none.
bool sample_pbr_base_direction(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, Vec3* wi);

}  // namespace sahara
