#pragma once
/// Scattering at a surface point: Lambertian, metal (perfect mirror or GGX
/// microfacet), dielectric (glass) and the glTF material (render/bsdf_pbr.h).
/// A closed set dispatched by a switch. Conventions: wo and wi are unit world
/// directions pointing away from the surface (wo towards the previous vertex);
/// eval returns f * |cos(theta_i)|.
#include <vector>

#include "math/sampling.h"
#include "render/ggx.h"
#include "scene/scene.h"

namespace sahara {

enum class BsdfKind : uint8_t { lambertian, mirror, ggx, dielectric, pbr, none };

/// Metal roughness below this is treated as a perfect mirror (GGX with a
/// tinier alpha is numerically a delta anyway).
inline constexpr float kMinGgxAlpha = 1e-3f;

/// pbr's clearcoat and sheen at one point (render/bsdf_layers.h); read only when `on`.
struct BsdfLayers {
    bool on = false;
    bool coat_frame = false;    ///< the coat's normal is not the base's: coat_normal holds it
    Vec3 coat_normal{0, 0, 1};  ///< in the base's local frame
    float clearcoat = 0, coat_roughness = 0, coat_alpha = 0;
    Rgb sheen{0.0f};
    float sheen_roughness = 0, sheen_alpha = 0;
};

/// pbr's thin film (KHR_materials_iridescence) at one point; read only when Bsdf::iridescent.
struct BsdfFilm {
    float weight = 0;          ///< how much of the film's Fresnel replaces the base's, in (0, 1]
    float ior = 1.3f;          ///< the film's
    float thickness = 0;       ///< nm, > 0
    Rgb dielectric_f0{0.04f};  ///< the dielectric base's F0 under the film, before the specular weight
    /// Schlick F0 that bounds the dielectric Fresnel with the film: the layer's
    /// F0 for the albedo scaling, and the cap of the Fresnel (bsdf_pbr.cpp)
    float bound_f0 = 0.04f;
    /// The clearcoat's weight over the film: where coated, the film's outside
    /// medium is the coat (KHR_materials_iridescence), not air.
    float coat = 0;
};

/// A BSDF instantiated at one surface point.
struct Bsdf {
    BsdfKind kind = BsdfKind::none;
    Rgb albedo{0.0f};            ///< Lambertian reflectance, the metal's F0, or pbr's base colour
    float alpha = 0;             ///< GGX roughness parameter (= roughness^2); pbr anisotropic: along frame.s
    float eta = 1;               ///< ior on the far side / ior on the side of wo (dielectric)
    Frame frame{Vec3(0, 0, 1)};  ///< around the shading normal
    Vec3 ng;                     ///< geometric normal on the side of wo
    // pbr only (render/bsdf_pbr.h)
    float roughness = 0;  ///< perceptual roughness, for the albedo tables
    /// KHR_materials_anisotropy: frame.s is the anisotropy direction, `alpha`
    /// the roughness along it and alpha_y the roughness across it.
    bool anisotropic = false;
    float alpha_y = 0;
    float metallic = 0;
    float f0 = 0.04f;     ///< dielectric layer's reflectance at normal incidence (largest channel)
    Rgb f0_color{0.04f};  ///< the same per channel (KHR_materials_specular colours it)
    float f90 = 1;        ///< the dielectric layer's reflectance at grazing angles (KHR_materials_specular)
    float transmission = 0;  ///< fraction of the base that refracts instead of diffusing
    bool thin = false;       ///< thin-walled: transmission without refraction
    /// The weight of the base colour's Lambertian lobe: (1 - metallic)
    /// (1 - transmission), times 1 - diffuse_transmission.
    float diffuse_share = 1;
    /// KHR_materials_diffuse_transmission: the share of the diffuse base that
    /// is a Lambertian transmission instead, and that lobe's weight (its colour
    /// times (1 - metallic) (1 - transmission) diffuse_transmission).
    float diffuse_transmission = 0;
    Rgb diffuse_transmit{0.0f};
    BsdfLayers layers;  ///< clearcoat and sheen over all of the above

    bool iridescent = false;  ///< `film` is on: KHR_materials_iridescence
    BsdfFilm film;

    bool is_delta() const { return kind == BsdfKind::mirror || kind == BsdfKind::dielectric; }
};

/// One sampled direction with its Monte Carlo weight f * |cos| / pdf.
struct BsdfSample {
    Vec3 wi;
    Rgb weight{0.0f};
    float pdf = 0;  ///< solid-angle density (1 for delta lobes: unused)
    bool delta = false;
    bool transmit = false;  ///< wi goes through the surface (spawn on the far side)
    float eta_scale = 1;    ///< radiance scale 1/eta^2 undone, for Russian roulette
};

/// Any material's colour at `si`: albedo factor x texture x interpolated vertex
/// colour (1 without). The Lambertian reflectance, the metal's F0, pbr's base
/// colour, and what the albedo image shows; every albedo is evaluated here so
/// that vertex colours tint all material types alike.
Rgb material_albedo(const MaterialDesc& m, const SurfaceInteraction& si,
                    const std::vector<TextureDesc>& textures);

/// The BSDF of material `m` at `si`. A path that carries one wavelength
/// (render/dispersion.h; 0: all of them) sees a pbr volume's ior at that wavelength.
Bsdf make_bsdf(const MaterialDesc& m, const SurfaceInteraction& si, const std::vector<TextureDesc>& textures,
               float wavelength_nm = 0.0f);

/// f(wo, wi) * |cos(theta_i)| and the density sample() would give wi; zero for delta BSDFs.
Rgb eval_bsdf(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf);

/// Samples wi given wo; u picks the direction, u_lobe a lobe (dielectric).
bool sample_bsdf(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, BsdfSample& s);

/// Exact unpolarised Fresnel reflectance of a dielectric interface for light
/// arriving at cos_i (>= 0) from the side of ior n_i, eta = n_t / n_i; 1 under
/// total internal reflection.
float fresnel_dielectric(float cos_i, float eta);

/// Schlick's approximation with reflectance f0 at normal incidence (used for metals).
Rgb fresnel_schlick(const Rgb& f0, float cos_i);
/// Schlick's approximation from f0 at normal incidence to f90 at grazing angles.
Rgb fresnel_schlick(const Rgb& f0, float f90, float cos_i);

/// Mirror reflection of w about n.
inline Vec3 reflect(const Vec3& w, const Vec3& n) { return n * (2.0f * dot(w, n)) - w; }

/// Refraction of wo (on the side n points to) into the far side; eta = n_t / n_i.
/// False under total internal reflection.
bool refract(const Vec3& wo, const Vec3& n, float eta, Vec3* wt);

}  // namespace sahara
