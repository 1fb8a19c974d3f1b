#include "render/bsdf_pbr.h"

#include <cmath>

#include "render/bsdf_layers.h"
#include "render/dispersion.h"
#include "render/ggx_albedo.h"
#include "render/ggx_aniso_albedo.h"
#include "render/sheen.h"
#include "render/thin_film.h"
#include "scene/texture.h"

namespace sahara {

namespace {

float mean(const Rgb& c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

Rgb lerp(const Rgb& a, const Rgb& b, float t) { return a * (1.0f - t) + b * t; }

/// Kulla-Conty's Fresnel factor of the compensation lobe: the part of the
/// energy that multiple bounces between microfacets keep, given F_avg.
float multiscatter_fresnel(float f_avg, float e_avg) {
    return f_avg * f_avg * e_avg / (1.0f - f_avg * (1.0f - e_avg));
}
Rgb multiscatter_fresnel(const Rgb& f_avg, float e_avg) {
    return {multiscatter_fresnel(f_avg.x, e_avg), multiscatter_fresnel(f_avg.y, e_avg),
            multiscatter_fresnel(f_avg.z, e_avg)};
}

/// Hemispherical average of Schlick's Fresnel: F0 + (F90 - F0) / 21.
float schlick_average(float f0, float f90) { return f0 + (f90 - f0) / 21.0f; }

/// The GGX functions of ggx.h for this material: anisotropic only where
/// KHR_materials_anisotropy made it so, so that isotropic materials keep their arithmetic.
float ggx_d(const Bsdf& b, const Vec3& wm) {
    return b.anisotropic ? ggx_d(wm, b.alpha, b.alpha_y) : ggx_d(wm, b.alpha);
}
float ggx_lambda(const Bsdf& b, const Vec3& w) {
    return b.anisotropic ? ggx_lambda(w, b.alpha, b.alpha_y) : ggx_lambda(w, b.alpha);
}
Vec3 sample_ggx_vndf(const Bsdf& b, const Vec3& wo, Vec2 u) {
    return sample_ggx_vndf(wo, b.alpha, b.anisotropic ? b.alpha_y : b.alpha, u);
}
float ggx_vndf_pdf(const Bsdf& b, const Vec3& wo, const Vec3& wm) {
    return b.anisotropic ? ggx_vndf_pdf(wo, wm, b.alpha, b.alpha_y) : ggx_vndf_pdf(wo, wm, b.alpha);
}
float ggx_reflection_pdf(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
    return b.anisotropic ? ggx_reflection_pdf(wo, wi, b.alpha, b.alpha_y)
                         : ggx_reflection_pdf(wo, wi, b.alpha);
}

/// The single-scattering albedo towards w and its hemispherical average, from the
/// table that fits the material: unequal alphas depend on w's azimuth too
/// (equal ones read the finer isotropic table, which the caller holds, so that
/// isotropic materials pay one test for this).
bool anisotropic_albedo(const Bsdf& b) { return b.anisotropic && b.alpha != b.alpha_y; }
GgxAlbedo ggx_albedo(const Bsdf& b, const GgxAlbedoTable& table, const Vec3& w) {
    return anisotropic_albedo(b) ? GgxAnisoAlbedoTable::get().at(w, b.alpha, b.alpha_y)
                                 : table.at(w.z, b.roughness);
}
GgxAlbedo ggx_albedo_average(const Bsdf& b, const GgxAlbedoTable& table) {
    return anisotropic_albedo(b) ? GgxAnisoAlbedoTable::get().average(b.alpha, b.alpha_y)
                                 : table.average(b.roughness);
}

/// Everything the lobes need that depends on the material only, from the tables.
struct PbrTerms {
    float e_avg = 1, one_minus_e_avg = 0;
    Rgb spec_ms{0.0f};         ///< F_ms mixed by metallic (dielectric: scalar F0, metal: base colour)
    float dielectric_ms = 0;   ///< F_ms of the dielectric layer alone
    float dielectric_avg = 0;  ///< Ed_avg: the dielectric layer's average albedo
    Rgb f0{0.04f};             ///< Schlick F0 of the specular lobe, mixed by metallic
    float f90 = 1;             ///< and its F90 (below 1 only with KHR_materials_specular)
    Rgb diffuse{0.0f};         ///< Lambertian base weight (1 - metallic)(1 - transmission) base
};

/// F_ms of a dielectric layer whose F0 has a colour (KHR_materials_specular).
Rgb tinted_dielectric_ms(const Bsdf& b, float e_avg) {
    return {multiscatter_fresnel(schlick_average(b.f0_color.x, b.f90), e_avg),
            multiscatter_fresnel(schlick_average(b.f0_color.y, b.f90), e_avg),
            multiscatter_fresnel(schlick_average(b.f0_color.z, b.f90), e_avg)};
}

PbrTerms pbr_terms(const Bsdf& b, const GgxAlbedo& avg) {
    PbrTerms t;
    t.e_avg = avg.e;
    t.one_minus_e_avg = 1.0f - avg.e;
    const Rgb base = b.albedo;
    t.f0 = lerp(b.f0_color, base, b.metallic);
    t.f90 = 1.0f - (1.0f - b.metallic) * (1.0f - b.f90);  // exactly 1 without the specular extension
    // The layer's albedo uses the largest channel of F0 (b.f0), as the extension's
    // fresnel_mix does, so that the base below never gets more than one channel lets through.
    t.dielectric_ms = multiscatter_fresnel(schlick_average(b.f0, b.f90), avg.e);
    const Rgb dielectric_ms = b.f0_color == Rgb(b.f0) ? Rgb(t.dielectric_ms) : tinted_dielectric_ms(b, avg.e);
    const Rgb metal_avg = base + (Rgb(1.0f) - base) * (1.0f / 21.0f);
    t.spec_ms = lerp(dielectric_ms, multiscatter_fresnel(metal_avg, avg.e), b.metallic);
    t.dielectric_avg = b.f0 * avg.e + (b.f90 - b.f0) * avg.e_schlick + t.one_minus_e_avg * t.dielectric_ms;
    t.diffuse = base * b.diffuse_share;
    return t;
}

/// Ed(mu): albedo of the dielectric layer (single and multiple scattering).
float dielectric_albedo(const Bsdf& b, const PbrTerms& t, const GgxAlbedo& e) {
    return b.f0 * e.e + (b.f90 - b.f0) * e.e_schlick + (1.0f - e.e) * t.dielectric_ms;
}

/// The film's reflectance at cos_theta (measured in air) over a base of
/// reflectance base_f0. Under a clearcoat of weight film.coat the film lies
/// in the coat (ior 1.5), which the layering does not bend rays through but
/// which the light crosses at the refracted angle: the outside ior and that
/// angle change, the angle in the film does not (Snell's invariant).
Rgb film_reflectance(const BsdfFilm& film, float cos_theta, const Rgb& base_f0) {
    const auto in_air = [&] { return thin_film_reflectance(cos_theta, film.ior, film.thickness, base_f0); };
    if (!(film.coat > 0)) return in_air();
    const float sin_sq = std::max(0.0f, 1.0f - cos_theta * cos_theta) / (kCoatIor * kCoatIor);
    const Rgb coated =
        thin_film_reflectance(std::sqrt(1.0f - sin_sq), film.ior, film.thickness, base_f0, kCoatIor);
    return film.coat < 1.0f ? lerp(in_air(), coated, film.coat) : coated;
}

/// KHR_materials_iridescence: Schlick's Fresnel and the film's mixed by the
/// film's weight, for the dielectric and the metal alike, then by metallic.
/// The dielectric one is capped by Schlick's curve from film.bound_f0, the F0
/// its albedo scaling uses, so that the base below never gets more than the
/// film leaves; the metal's needs no cap, the film reflecting at most 1.
Rgb iridescent_fresnel(const Bsdf& b, float cos_theta) {
    const BsdfFilm& film = b.film;
    Rgb dielectric(0.0f), metal(0.0f);
    if (b.metallic < 1.0f) {
        const Rgb thin = film_reflectance(film, cos_theta, film.dielectric_f0) * b.f90;
        dielectric = min(lerp(fresnel_schlick(b.f0_color, b.f90, cos_theta), thin, film.weight),
                         fresnel_schlick(Rgb(film.bound_f0), b.f90, cos_theta));
    }
    if (b.metallic > 0.0f)
        metal = lerp(fresnel_schlick(b.albedo, cos_theta), film_reflectance(film, cos_theta, b.albedo),
                     film.weight);
    return lerp(dielectric, metal, b.metallic);
}

/// What reaches the Lambertian lobes below the dielectric layer for light
/// from wo leaving towards wi (either side): (1 - Ed(mu_o)) (1 - Ed(mu_i)) /
/// (1 - Ed_avg), symmetric so that they stay reciprocal. A layer that reflects
/// everything (F0 clamped to 1 by KHR_materials_specular) leaves them nothing.
float diffuse_scale(const Bsdf& b, const PbrTerms& t, const GgxAlbedo& eo, const GgxAlbedo& ei) {
    const float base_avg = 1.0f - t.dielectric_avg;
    return base_avg > 1e-6f
               ? (1.0f - dielectric_albedo(b, t, eo)) * (1.0f - dielectric_albedo(b, t, ei)) / base_avg
               : 0.0f;
}

/// Single-scattering GGX reflection, f cos.
Rgb eval_specular(const Bsdf& b, const PbrTerms& t, const Vec3& wo, const Vec3& wi) {
    const Vec3 wm = normalize(wo + wi);
    const float lo = ggx_lambda(b, wo), li = ggx_lambda(b, wi);
    const float g2 = 1.0f / (1.0f + lo + li);
    const float cos_m = std::abs(dot(wo, wm));
    const Rgb fresnel = b.iridescent ? iridescent_fresnel(b, cos_m) : fresnel_schlick(t.f0, t.f90, cos_m);
    return fresnel * (ggx_d(b, wm) * g2 / (4.0f * wo.z));
}

/// The half vector of a refraction from wo (outside, +z) to wi (below), facing +z.
Vec3 refraction_half_vector(const Vec3& wo, const Vec3& wi, float eta) {
    Vec3 wm = normalize(wi * eta + wo);
    return wm.z < 0 ? -wm : wm;
}

/// Rough refraction (Walter et al. 2007), f |cos| and its sampling density.
/// A thin wall transmits like a reflection mirrored through the surface:
/// the light leaves on the far side without bending.
Rgb eval_transmission(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    *pdf = 0;
    const float lo = ggx_lambda(b, wo), li = ggx_lambda(b, wi);
    const Rgb tint = b.albedo * ((1.0f - b.metallic) * b.transmission);
    if (b.thin) {
        const Vec3 wr(wi.x, wi.y, -wi.z);
        const Vec3 wm = normalize(wo + wr);
        *pdf = ggx_reflection_pdf(b, wo, wr);
        const float fresnel_t = 1.0f - fresnel_schlick(Rgb(b.f0), b.f90, dot(wo, wm)).x;
        return tint * (fresnel_t * ggx_d(b, wm) / (1.0f + lo + li) / (4.0f * wo.z));
    }
    const Vec3 wm = refraction_half_vector(wo, wi, b.eta);
    const float o_m = dot(wo, wm), i_m = dot(wi, wm);
    if (o_m <= 0 || i_m >= 0) return Rgb(0.0f);  // not a refraction through this microfacet
    const float denom = (i_m + o_m / b.eta) * (i_m + o_m / b.eta);
    const float fresnel_t = 1.0f - b.f90 * fresnel_dielectric(o_m, b.eta);
    *pdf = ggx_vndf_pdf(b, wo, wm) * std::abs(i_m) / denom;
    // Radiance is compressed by eta^2 entering the denser side, as for `dielectric`.
    const float f =
        fresnel_t * ggx_d(b, wm) / (1.0f + lo + li) * std::abs(i_m * o_m) / (wo.z * denom) / (b.eta * b.eta);
    return tint * f;
}

/// The Lambertian transmission (wi below), f |cos|; adds its share of the density to *pdf.
Rgb eval_diffuse_transmission(const Bsdf& b, const PbrLobeWeights& p, const Vec3& wo, const Vec3& wi,
                              float* pdf) {
    const GgxAlbedoTable& table = GgxAlbedoTable::get();
    const PbrTerms t = pbr_terms(b, ggx_albedo_average(b, table));
    const Vec3 wi_up(wi.x, wi.y, -wi.z);  // the albedo tables are of the upper side
    const float cos_pi = -wi.z * kInvPi;
    *pdf += p.diffuse_transmit * cos_pi;
    return b.diffuse_transmit *
           (diffuse_scale(b, t, ggx_albedo(b, table, wo), ggx_albedo(b, table, wi_up)) * cos_pi);
}

/// A transmitted direction for the visible normal wm; false if there is none.
bool sample_transmission(const Bsdf& b, const Vec3& wo, const Vec3& wm, Vec3* wi) {
    if (b.thin) {
        const Vec3 wr = reflect(wo, wm);
        *wi = Vec3(wr.x, wr.y, -wr.z);
        return wr.z > 0;
    }
    return refract(wo, wm, b.eta, wi) && wi->z < 0;
}

/// The UVs a texture reads: set 0 or 1 (glTF texCoord).
Vec2 texcoord(const SurfaceInteraction& si, const std::vector<TextureDesc>& textures, int texture) {
    return texture >= 0 && textures[size_t(texture)].texcoord == 1 ? si.uv1 : si.uv;
}

/// The shading normal bent by a tangent-space normal map (glTF: +Y towards
/// increasing v, xy scaled by `scale`). The map describes the front
/// side; a back face sees the same bumps from behind, so the frame is built
/// on the front side and the result turned around.
Vec3 mapped_normal(int texture, float scale, const SurfaceInteraction& si,
                   const std::vector<TextureDesc>& textures) {
    if (length_squared(si.tangent) <= 0) return si.ns;
    const Vec3 n_front = si.front_face ? si.ns : -si.ns;
    const Vec3 t0 = si.tangent - n_front * dot(n_front, si.tangent);
    if (length_squared(t0) <= 1e-12f) return si.ns;
    const Vec3 t = normalize(t0);
    const Vec3 bt = cross(n_front, t) * si.tangent_sign;
    const Rgb c = sample_texture_rgb(textures[size_t(texture)], texcoord(si, textures, texture));
    const float x = (2.0f * c.x - 1.0f) * scale, y = (2.0f * c.y - 1.0f) * scale;
    const float z = 2.0f * c.z - 1.0f;
    const Vec3 n = t * x + bt * y + n_front * z;
    if (!(length_squared(n) > 0)) return si.ns;
    const Vec3 ns = si.front_face ? normalize(n) : -normalize(n);
    return dot(ns, si.ng) > 0 ? ns : si.ns;  // a map must not turn the surface away from the viewer's side
}

/// One channel of a data texture (read linear), or 1 without one.
float texture_channel(int texture, int channel, const SurfaceInteraction& si,
                      const std::vector<TextureDesc>& textures) {
    if (texture < 0) return 1.0f;
    float alpha = 1.0f;
    const Rgb c = sample_texture_rgb(textures[size_t(texture)], texcoord(si, textures, texture),
                                     channel == 3 ? &alpha : nullptr);
    return channel == 3 ? alpha : c[channel];
}

bool has_specular_inputs(const MaterialDesc& m) {
    return m.specular != 1.0f || m.specular_texture >= 0 || m.specular_color != Rgb(1.0f) ||
           m.specular_color_texture >= 0;
}

/// KHR_materials_specular: F0 = min(F0(ior) x colour, 1) x weight, F90 = weight.
void apply_specular(Bsdf& b, const MaterialDesc& m, const SurfaceInteraction& si,
                    const std::vector<TextureDesc>& textures) {
    float weight = m.specular * texture_channel(m.specular_texture, 3, si, textures);
    Rgb color = m.specular_color;
    if (m.specular_color_texture >= 0)
        color *= sample_texture_rgb(textures[size_t(m.specular_color_texture)],
                                    texcoord(si, textures, m.specular_color_texture));
    weight = std::clamp(weight, 0.0f, 1.0f);
    const Rgb f0 = Rgb(b.f0) * color;
    b.f0_color = Rgb(std::min(f0.x, 1.0f), std::min(f0.y, 1.0f), std::min(f0.z, 1.0f)) * weight;
    b.f0 = max_component(b.f0_color);
    b.f90 = weight;
}

/// KHR_materials_iridescence at si: the film's weight (factor x texture R) and
/// thickness (texture G between the minimum and the maximum, else the
/// maximum). A film of no weight or thickness leaves the material untouched.
/// The dielectric layer's F0 becomes the bound of what it reflects with the
/// film, so that the albedo scaling keeps the whole energy conserving. Reads
/// the clearcoat's weight from b.layers (set before).
void set_iridescence(Bsdf& b, const IridescenceDesc& d, const SurfaceInteraction& si,
                     const std::vector<TextureDesc>& textures) {
    const float weight = std::clamp(d.factor * texture_channel(d.texture, 0, si, textures), 0.0f, 1.0f);
    float thickness = d.thickness_max;
    if (d.thickness_texture >= 0)
        thickness = d.thickness_min + (d.thickness_max - d.thickness_min) *
                                          texture_channel(d.thickness_texture, 1, si, textures);
    if (!(weight > 0) || !(thickness > 0)) return;
    BsdfFilm& film = b.film;
    film.weight = weight;
    film.ior = d.ior;
    film.thickness = thickness;
    // The film lies on the dielectric before KHR_materials_specular's weight,
    // which scales what the two reflect together.
    film.dielectric_f0 = b.f90 > 0 ? b.f0_color / b.f90 : b.f0_color;
    film.coat = b.layers.clearcoat;
    float film_f0 = thin_film_reflectance_bound(d.ior, film.dielectric_f0);
    if (film.coat > 0)
        film_f0 = std::max(film_f0, thin_film_reflectance_bound(d.ior, film.dielectric_f0, kCoatIor));
    film_f0 *= b.f90;
    film.bound_f0 = std::min(1.0f, b.f0 + weight * std::max(0.0f, film_f0 - b.f0));
    b.f0 = film.bound_f0;
    b.iridescent = true;
}

/// The coat's weight at si: clearcoat x its texture's R.
float coat_weight(const PbrLayersDesc& d, const SurfaceInteraction& si,
                  const std::vector<TextureDesc>& textures) {
    return std::clamp(d.clearcoat * texture_channel(d.clearcoat_texture, 0, si, textures), 0.0f, 1.0f);
}

/// The coat's normal at si (world). Without its own normal map the coat follows
/// the interpolated normal, not the base's normal map (as the extension says): a
/// smooth lacquer over bumps.
Vec3 coat_normal(const PbrLayersDesc& d, const SurfaceInteraction& si,
                 const std::vector<TextureDesc>& textures) {
    return d.clearcoat_normal_texture >= 0
               ? mapped_normal(d.clearcoat_normal_texture, d.clearcoat_normal_scale, si, textures)
               : si.ns;
}

/// The tangent the anisotropy direction is measured from, orthogonal to the
/// front-side normal n: the mesh's (glTF TANGENT, or generated from the UVs as
/// for normal maps), else, on surfaces without one (analytic shapes), the
/// direction around the scene's z axis (a sphere's increasing u), or x where
/// the surface faces along z. Zero if none can be built.
Vec3 anisotropy_tangent(const SurfaceInteraction& si, const Vec3& n) {
    Vec3 t = si.tangent;
    if (length_squared(t) <= 0) {
        t = cross(Vec3(0, 0, 1), n);
        if (length_squared(t) <= 1e-8f) t = Vec3(1, 0, 0);
    }
    t = t - n * dot(n, t);
    return length_squared(t) > 1e-12f ? normalize(t) : Vec3(0.0f);
}

/// KHR_materials_anisotropy: the direction (texture RG in [-1, 1] on the tangent
/// and bitangent, else the tangent) turned by the rotation, and the strength
/// (factor x texture B). The frame's first axis becomes that direction, with
/// alpha_t = mix(alpha, 1, strength^2) along it and alpha across it. A
/// strength of 0 leaves the material isotropic.
///
/// The albedo tables (multiple-scattering compensation, the base's scaling)
/// then come from GgxAnisoAlbedoTable, which follows the two alphas and the
/// azimuth of each direction.
void set_anisotropy(Bsdf& b, const MaterialDesc& m, const SurfaceInteraction& si,
                    const std::vector<TextureDesc>& textures) {
    float strength = m.anisotropy;
    float dx = 1.0f, dy = 0.0f;
    if (m.anisotropy_texture >= 0) {
        const Rgb c = sample_texture_rgb(textures[size_t(m.anisotropy_texture)],
                                         texcoord(si, textures, m.anisotropy_texture));
        const float x = 2.0f * c.x - 1.0f, y = 2.0f * c.y - 1.0f;
        if (x * x + y * y > 1e-8f) {
            dx = x;
            dy = y;
        }
        strength *= c.z;
    }
    strength = std::clamp(strength, 0.0f, 1.0f);
    if (!(strength > 0)) return;
    const float cr = std::cos(m.anisotropy_rotation), sr = std::sin(m.anisotropy_rotation);
    const float rx = cr * dx - sr * dy, ry = sr * dx + cr * dy;
    // The tangent frame is built on the front side, as for normal maps.
    const Vec3 n_front = si.front_face ? si.ns : -si.ns;
    const Vec3 t = anisotropy_tangent(si, n_front);
    if (length_squared(t) <= 0) return;
    const Vec3 bt = cross(n_front, t) * si.tangent_sign;
    const Vec3 n = b.frame.n;  // possibly bent by a normal map
    const Vec3 d = t * rx + bt * ry;
    const Vec3 d_plane = d - n * dot(n, d);
    if (length_squared(d_plane) <= 1e-12f) return;
    b.frame = Frame(n, normalize(d_plane));
    b.anisotropic = true;
    b.alpha_y = b.alpha;
    b.alpha = b.alpha + (1.0f - b.alpha) * (strength * strength);
}

/// KHR_materials_diffuse_transmission at si: the share (factor x texture A)
/// and the colour (factor x texture RGB).
void set_diffuse_transmission(Bsdf& b, const MaterialDesc& m, const SurfaceInteraction& si,
                              const std::vector<TextureDesc>& textures) {
    const float share =
        std::clamp(m.diffuse_transmission * texture_channel(m.diffuse_transmission_texture, 3, si, textures),
                   0.0f, 1.0f);
    Rgb color = m.diffuse_transmission_color;
    if (m.diffuse_transmission_color_texture >= 0)
        color *= sample_texture_rgb(textures[size_t(m.diffuse_transmission_color_texture)],
                                    texcoord(si, textures, m.diffuse_transmission_color_texture));
    color = Rgb(std::clamp(color.x, 0.0f, 1.0f), std::clamp(color.y, 0.0f, 1.0f),
                std::clamp(color.z, 0.0f, 1.0f));
    b.diffuse_transmission = share;
    b.diffuse_transmit = color * (b.diffuse_share * share);
    b.diffuse_share *= 1.0f - share;
}

/// KHR_materials_clearcoat and KHR_materials_sheen at si: factors times textures.
void set_pbr_layers(Bsdf& b, const PbrLayersDesc& d, const SurfaceInteraction& si,
                    const std::vector<TextureDesc>& textures) {
    BsdfLayers& l = b.layers;
    l.clearcoat = coat_weight(d, si, textures);
    l.coat_roughness = std::clamp(
        d.clearcoat_roughness * texture_channel(d.clearcoat_roughness_texture, 1, si, textures), 0.0f, 1.0f);
    l.coat_alpha = pbr_alpha(l.coat_roughness);
    Rgb sheen = d.sheen_color;
    if (d.sheen_color_texture >= 0)
        sheen = sheen * sample_texture_rgb(textures[size_t(d.sheen_color_texture)],
                                           texcoord(si, textures, d.sheen_color_texture));
    l.sheen = Rgb(std::clamp(sheen.x, 0.0f, 1.0f), std::clamp(sheen.y, 0.0f, 1.0f),
                  std::clamp(sheen.z, 0.0f, 1.0f));
    l.sheen_roughness = std::clamp(
        d.sheen_roughness * texture_channel(d.sheen_roughness_texture, 3, si, textures), 0.0f, 1.0f);
    l.sheen_alpha = sheen_alpha(l.sheen_roughness);
    if (l.clearcoat > 0 && (d.clearcoat_normal_texture >= 0 || !(b.frame.n == si.ns))) {
        l.coat_normal = normalize(b.frame.to_local(coat_normal(d, si, textures)));
        l.coat_frame = true;
    }
    l.on = l.clearcoat > 0 || max_component(l.sheen) > 0;
}

}  // namespace

// Declared in render/bsdf.h; here because it shares texcoord with the pbr inputs.
Rgb material_albedo(const MaterialDesc& m, const SurfaceInteraction& si,
                    const std::vector<TextureDesc>& textures) {
    return eval_color(m.albedo, textures, si.p, texcoord(si, textures, m.albedo.texture)) * si.color;
}

Rgb pbr_emission(const MaterialDesc& m, const SurfaceInteraction& si,
                 const std::vector<TextureDesc>& textures, const Vec3& wo) {
    const Rgb le = eval_color(m.radiance, textures, si.p, texcoord(si, textures, m.radiance.texture));
    if (!(m.layers.clearcoat > 0) || !(max_component(le) > 0)) return le;  // uncoated: one test
    const float cos_coat = std::abs(dot(coat_normal(m.layers, si, textures), normalize(wo)));
    return le * (1.0f - coat_fresnel(coat_weight(m.layers, si, textures), cos_coat));
}

void make_pbr_bsdf(Bsdf& b, const MaterialDesc& m, const SurfaceInteraction& si,
                   const std::vector<TextureDesc>& textures, float wavelength_nm) {
    b.kind = BsdfKind::pbr;
    b.albedo = material_albedo(m, si, textures);
    float roughness = m.roughness, metallic = m.metallic, transmission = m.transmission;
    if (m.metallic_roughness_texture >= 0) {
        const Rgb c = sample_texture_rgb(textures[size_t(m.metallic_roughness_texture)],
                                         texcoord(si, textures, m.metallic_roughness_texture));
        roughness *= c.y;
        metallic *= c.z;
    }
    if (m.transmission_texture >= 0)
        transmission *= sample_texture_rgb(textures[size_t(m.transmission_texture)],
                                           texcoord(si, textures, m.transmission_texture))
                            .x;
    b.roughness = std::clamp(roughness, 0.0f, 1.0f);
    b.alpha = pbr_alpha(b.roughness);
    b.metallic = std::clamp(metallic, 0.0f, 1.0f);
    b.transmission = std::clamp(transmission, 0.0f, 1.0f);
    b.diffuse_share = (1.0f - b.metallic) * (1.0f - b.transmission);
    if (m.diffuse_transmission > 0) set_diffuse_transmission(b, m, si, textures);
    // The whole interface, reflection included, has the ior of the path's wavelength.
    const float ior =
        wavelength_nm > 0.0f && disperses(m) ? dispersed_ior(m.ior, m.dispersion, wavelength_nm) : m.ior;
    const float r = (ior - 1.0f) / (ior + 1.0f);
    b.f0 = r * r;
    b.f0_color = Rgb(b.f0);
    if (has_specular_inputs(m)) apply_specular(b, m, si, textures);
    b.thin = m.thin_walled;
    b.eta = m.thin_walled ? 1.0f : si.front_face ? ior : 1.0f / ior;
    if (m.normal_texture >= 0) b.frame = Frame(mapped_normal(m.normal_texture, m.normal_scale, si, textures));
    if (m.anisotropy > 0) set_anisotropy(b, m, si, textures);
    if (m.layers.any()) set_pbr_layers(b, m.layers, si, textures);
    if (m.iridescence.factor > 0) set_iridescence(b, m.iridescence, si, textures);
}

Rgb pbr_fresnel(const Bsdf& b, float cos_theta) {
    if (b.iridescent) return iridescent_fresnel(b, cos_theta);
    return fresnel_schlick(lerp(b.f0_color, b.albedo, b.metallic),
                           1.0f - (1.0f - b.metallic) * (1.0f - b.f90), cos_theta);
}

PbrLobeWeights pbr_lobe_weights(const Bsdf& b, const Vec3& wo) {
    const GgxAlbedoTable& table = GgxAlbedoTable::get();
    const PbrTerms t = pbr_terms(b, ggx_albedo_average(b, table));
    const GgxAlbedo e = ggx_albedo(b, table, wo);
    PbrLobeWeights w;
    const float f0 = mean(t.f0);
    w.specular = f0 * e.e + (t.f90 - f0) * e.e_schlick;
    w.cosine = mean(t.spec_ms) * (1.0f - e.e) + mean(t.diffuse) * (1.0f - dielectric_albedo(b, t, e));
    w.transmit = (1.0f - b.metallic) * b.transmission * mean(b.albedo) * (1.0f - f0);
    float sum = w.specular + w.cosine + w.transmit;
    if (b.diffuse_transmission > 0) {
        w.diffuse_transmit = mean(b.diffuse_transmit) * (1.0f - dielectric_albedo(b, t, e));
        sum += w.diffuse_transmit;
    }
    if (!(sum > 0)) return {};
    w.total = sum;
    w.specular /= sum;
    w.cosine /= sum;
    w.transmit /= sum;
    w.diffuse_transmit /= sum;
    return w;
}

Rgb eval_pbr(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    return b.layers.on ? eval_pbr_layered(b, wo, wi, pdf) : eval_pbr_base(b, wo, wi, pdf);
}

Rgb eval_pbr_base(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    *pdf = 0;
    if (wo.z <= 0 || wi.z == 0) return Rgb(0.0f);
    const PbrLobeWeights p = pbr_lobe_weights(b, wo);
    if (wi.z < 0) {
        Rgb f(0.0f);
        if (p.transmit > 0) {
            float pdf_t = 0;
            f = eval_transmission(b, wo, wi, &pdf_t);
            *pdf = p.transmit * pdf_t;
        }
        if (p.diffuse_transmit > 0) f += eval_diffuse_transmission(b, p, wo, wi, pdf);
        return f;
    }
    const GgxAlbedoTable& table = GgxAlbedoTable::get();
    const PbrTerms t = pbr_terms(b, ggx_albedo_average(b, table));
    const GgxAlbedo eo = ggx_albedo(b, table, wo), ei = ggx_albedo(b, table, wi);
    Rgb f = eval_specular(b, t, wo, wi);
    const float cos_pi = wi.z * kInvPi;
    if (t.one_minus_e_avg > 1e-6f)
        f += t.spec_ms * ((1.0f - eo.e) * (1.0f - ei.e) / t.one_minus_e_avg * cos_pi);
    f += t.diffuse * (diffuse_scale(b, t, eo, ei) * cos_pi);
    *pdf = p.specular * ggx_reflection_pdf(b, wo, wi) + p.cosine * cos_pi;
    return f;
}

bool sample_pbr_base_direction(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, Vec3* wi) {
    const PbrLobeWeights p = pbr_lobe_weights(b, wo);
    if (u_lobe < p.specular) {
        *wi = reflect(wo, sample_ggx_vndf(b, wo, u));
        return wi->z > 0;
    }
    if (u_lobe < p.specular + p.cosine) {
        *wi = sample_cosine_hemisphere(u);
        return true;
    }
    if (u_lobe < p.specular + p.cosine + p.transmit || !(p.diffuse_transmit > 0))
        return p.transmit > 0 && sample_transmission(b, wo, sample_ggx_vndf(b, wo, u), wi);
    const Vec3 d = sample_cosine_hemisphere(u);
    *wi = Vec3(d.x, d.y, -d.z);
    return true;
}

bool sample_pbr(const Bsdf& b, const Vec3& wo, Vec2 u, float u_lobe, BsdfSample& s) {
    if (wo.z <= 0) return false;
    Vec3 wi;
    if (!(b.layers.on ? sample_pbr_layered_direction(b, wo, u, u_lobe, &wi)
                      : sample_pbr_base_direction(b, wo, u, u_lobe, &wi)))
        return false;
    float pdf = 0;
    const Rgb f = eval_pbr(b, wo, wi, &pdf);
    if (!(pdf > 0)) return false;
    s.wi = wi;
    s.pdf = pdf;
    s.weight = f / pdf;
    s.delta = false;
    s.transmit = wi.z < 0;
    s.eta_scale = s.transmit ? b.eta * b.eta : 1.0f;
    return true;
}

}  // namespace sahara
