#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/spawn.h"
#include "math/sampling.h"
#include "render/background.h"
#include "render/bsdf.h"
#include "render/bsdf_pbr.h"
#include "render/dispersion.h"
#include "render/lights.h"
#include "scene/texture.h"

namespace sahara {

namespace {

/// Paths shorter than this never face Russian roulette.
constexpr int kRouletteStartDepth = 4;

/// Unlit surfaces one path or shadow ray passes at most (each pass moves on along the
/// ray, so the bound only guards against pathological stacks of coplanar sheets).
constexpr int kMaxUnlitPasses = 64;

/// What light sampling a kernel does. `none`: the scene has nothing to sample
/// (or BSDF sampling only is forced); `delta`: point/directional lights only,
/// so no MIS is ever needed; `mis`: everything; `light_only`: for tests.
enum class Strategy : uint8_t { none, delta, mis, light_only };

/// Weight of emission found by BSDF sampling from a non-delta vertex whose
/// direction light sampling could also have produced with density light_pdf.
template <Strategy S>
float hit_weight(float bsdf_pdf, float light_pdf) {
    if constexpr (S == Strategy::mis)
        return power_heuristic(bsdf_pdf, light_pdf);
    else if constexpr (S == Strategy::light_only)
        return 0.0f;
    else
        return 1.0f;
}

/// The Lambertian-only kernels' BSDF: no dispatch, no frame until sampling.
struct LambertShading {
    Rgb albedo;
    Vec3 ns, ng;
    bool is_delta() const { return false; }
};

inline Rgb eval_shading(const LambertShading& b, const Vec3&, const Vec3& wi, float* pdf) {
    const float cos = dot(wi, b.ns);
    if (dot(wi, b.ng) <= 0 || cos <= 0) {
        *pdf = 0;
        return Rgb(0.0f);
    }
    *pdf = cos * kInvPi;
    return b.albedo * (cos * kInvPi);
}
inline Rgb eval_shading(const Bsdf& b, const Vec3& wo, const Vec3& wi, float* pdf) {
    return eval_bsdf(b, wo, wi, pdf);
}

inline bool sample_shading(const LambertShading& b, const Vec3&, Sampler& sampler, BsdfSample& bs) {
    const Vec3 local = sample_cosine_hemisphere(sampler.next_2d());
    bs.wi = Frame(b.ns).to_world(local);
    bs.weight = b.albedo;
    bs.pdf = local.z * kInvPi;
    return dot(bs.wi, b.ng) > 0;  // below the geometric surface: absorbed
}
inline bool sample_shading(const Bsdf& b, const Vec3& wo, Sampler& sampler, BsdfSample& bs) {
    const Vec2 u = sampler.next_2d();
    return sample_bsdf(b, wo, u, sampler.next_1d(), bs);
}

template <bool kLambertOnly>
auto make_shading(const MaterialDesc& m, const SurfaceInteraction& si,
                  const std::vector<TextureDesc>& textures, [[maybe_unused]] float wavelength_nm) {
    if constexpr (kLambertOnly)
        return LambertShading{material_albedo(m, si, textures), si.ns, si.ng};
    else
        return make_bsdf(m, si, textures, wavelength_nm);
}

/// Next-event estimation at a non-delta vertex: one emitter, one shadow ray
/// (which passes unlit surfaces in scenes that have them, kUnlit).
template <Strategy S, bool kUnlit, class Shading>
Rgb direct_light(const Scene& scene, const SurfaceInteraction& si, const Shading& bsdf, const Vec3& wo,
                 float time, float u_select, Vec2 u) {
    LightSample ls;
    if (!sample_light(scene, si.p, time, u_select, u, ls)) return Rgb(0.0f);
    float bsdf_pdf = 0;
    const Rgb f_cos = eval_shading(bsdf, wo, ls.wi, &bsdf_pdf);
    if (max_component(f_cos) <= 0 || max_component(ls.li) <= 0) return Rgb(0.0f);
    const Ray shadow = shadow_ray(si.p, si.ng, ls, time);
    if (kUnlit ? occluded_except_unlit(scene, shadow, shadow_cache(ls.emitter))
               : scene.occluded(shadow, shadow_cache(ls.emitter)))
        return Rgb(0.0f);
    const float w = (S == Strategy::mis && !ls.delta) ? power_heuristic(ls.pdf, bsdf_pdf) : 1.0f;
    return f_cos * ls.li * (w / ls.pdf);
}

/// Where the previous scattering event was, for MIS weights of emission found next.
struct PrevVertex {
    Vec3 p;
    float pdf = 0;
    bool delta = true;  // emitters seen by the camera or through a mirror count fully
};

/// Emission of an emissive surface hit by the path, MIS-weighted against light sampling.
template <Strategy S>
Rgb hit_emission(const Scene& scene, const Ray& ray, const Hit& hit, const SurfaceInteraction& si,
                 const MaterialDesc& mat, const PrevVertex& prev) {
    if (!si.front_face) return Rgb(0.0f);
    float w = 1;
    if constexpr (S == Strategy::mis || S == Strategy::light_only) {
        const uint32_t e = emitter_of_hit(scene, hit);
        if (!prev.delta && e != kNoEmitter)
            w = hit_weight<S>(prev.pdf, area_light_pdf(scene, e, prev.p, si.p, si.ng, ray.time));
    }
    return eval_color(mat.radiance, scene.textures, si.p, si.uv) * w;
}

/// Emission of a glowing pbr surface. Its front is a sampled area light (MIS-weighted
/// as in hit_emission); its back (a double-sided material glows on both sides) is
/// never light-sampled, so BSDF sampling counts it in full.
template <Strategy S>
Rgb pbr_hit_emission(const Scene& scene, const Ray& ray, const Hit& hit, const SurfaceInteraction& si,
                     const MaterialDesc& mat, const PrevVertex& prev) {
    const Rgb le = pbr_emission(mat, si, scene.textures, -ray.dir);
    if constexpr (S == Strategy::mis || S == Strategy::light_only) {
        if (si.front_face && !prev.delta && max_component(le) > 0) {
            const uint32_t e = emitter_of_hit(scene, hit);
            if (e != kNoEmitter)
                return le * hit_weight<S>(prev.pdf, area_light_pdf(scene, e, prev.p, si.p, si.ng, ray.time));
        }
    }
    return le;
}

/// The background seen by a path that leaves the scene, MIS-weighted against envmap sampling.
template <Strategy S>
Rgb escaped(const Scene& scene, const Ray& ray, const PrevVertex& prev) {
    float w = 1;
    if constexpr (S == Strategy::mis || S == Strategy::light_only)
        if (!prev.delta && scene.envmap_emitter != kNoEmitter)
            w = hit_weight<S>(prev.pdf, envmap_light_pdf(scene, ray.dir));
    return eval_background(scene.background, ray.dir) * w;
}

/// The medium a path travels in: a pbr volume's Beer-Lambert absorption
/// (KHR_materials_volume), or none. Entered by refraction into the front of an
/// attenuating pbr surface, left by any other refraction (nested volumes are not tracked).
struct Medium {
    bool absorbs = false;
    Rgb sigma{0.0f};  ///< per unit length: light decays to attenuation_color over attenuation_distance

    /// The medium after a refraction through `m` (from its front when `entering`).
    static Medium after_refraction(const MaterialDesc& m, bool entering) {
        Medium out;
        if (!entering || m.type != MaterialType::pbr || m.thin_walled ||
            !std::isfinite(m.attenuation_distance) || !(m.attenuation_distance > 0.0f))
            return out;
        for (int c = 0; c < 3; ++c) {
            const float color = std::clamp(m.attenuation_color[c], 0.0f, 1.0f);
            // Colour 0 absorbs everything: -log(0) = inf, kept finite so that distance 0 gives 1.
            out.sigma[c] =
                std::min(-std::log(color) / m.attenuation_distance, std::numeric_limits<float>::max());
        }
        out.absorbs = max_component(out.sigma) > 0.0f;
        return out;
    }
    /// Transmittance over `distance` (infinite: the path left an open mesh from inside).
    Rgb transmittance(float distance) const {
        Rgb t;
        for (int c = 0; c < 3; ++c) t[c] = sigma[c] > 0.0f ? std::exp(-sigma[c] * distance) : 1.0f;
        return t;
    }
};

/// The next hit along `ray`: the packet's answer when the camera ray was traced
/// in one (`first`), else a trace.
inline bool next_hit(const Scene& scene, Ray& ray, const Hit* first, Hit& hit) {
    if (!first) return scene.intersect(ray, hit);
    hit = *first;
    if (hit.hit()) ray.tmax = hit.t;
    return hit.hit();
}

/// Unlit surfaces (glTF KHR_materials_unlit) the way Blender's glTF importer
/// builds them for Cycles: the camera ray sees the colour as it is (the path
/// ends: false), every later ray goes on behind the surface as if it were not
/// there (true). They neither light nor shadow nor reflect in anything, so
/// they add no energy.
inline bool pass_unlit(const Scene& scene, const SurfaceInteraction& si, const MaterialDesc& mat,
                       const Hit& hit, int depth, const Rgb& beta, Rgb& radiance, Ray& ray) {
    if (depth == 1) {
        radiance += beta * material_albedo(mat, si, scene.textures);
        return false;
    }
    ray.tmin = hit.t;  // the next hit beyond this one: (tmin, tmax) is open
    ray.tmax = kInfinity;
    return true;
}

/// Russian roulette: false ends the path, true scales beta to keep the estimate unbiased.
inline bool survive_roulette(Sampler& sampler, Rgb& beta, float eta_scale) {
    const float survive = std::min(1.0f, max_component(beta) * eta_scale);
    if (sampler.next_1d() >= survive) return false;
    beta /= survive;
    return true;
}

/// One path. D rays at most, camera ray included; a shadow ray counts as the
/// next ray, so direct light is gathered only below max_depth. kUnlit: the
/// scene has unlit materials.
template <Strategy S, bool kLambertOnly, bool kUnlit = false>
Rgb path_kernel(const Scene& scene, Ray ray, Sampler& sampler, int max_depth, const Hit* first = nullptr) {
    // The plain Lambertian kernel is chosen only for scenes without any emission.
    constexpr bool kEmission = !(S == Strategy::none && kLambertOnly);
    Rgb radiance(0.0f), beta(1.0f);
    float eta_scale = 1;  // undoes the 1/eta^2 of refraction for Russian roulette
    PrevVertex prev;
    Medium medium;
    float wavelength =
        0;  // nm once a dispersive volume made the path carry one channel (render/dispersion.h)
    [[maybe_unused]] int unlit_passes = 0;
    for (int depth = 1; depth <= max_depth; ++depth) {
        Hit hit;
        const bool found = next_hit(scene, ray, depth == 1 ? first : nullptr, hit);
        if constexpr (!kLambertOnly)
            if (medium.absorbs)
                beta *= medium.transmittance(found ? (hit.t - ray.tmin) * length(ray.dir) : kInfinity);
        if (!found) {
            radiance += beta * escaped<S>(scene, ray, prev);
            break;
        }
        const SurfaceInteraction si = scene.interact(ray, hit);
        const MaterialDesc& mat = scene.materials[si.material];
        if (mat.type == MaterialType::emissive) {
            if constexpr (kEmission) radiance += beta * hit_emission<S>(scene, ray, hit, si, mat, prev);
            break;
        }
        if constexpr (kUnlit)
            if (mat.type == MaterialType::unlit) {  // no scattering event: the same depth goes on
                if (!pass_unlit(scene, si, mat, hit, depth, beta, radiance, ray) ||
                    ++unlit_passes > kMaxUnlitPasses)
                    break;
                --depth;
                continue;
            }
        if constexpr (kEmission)
            radiance += beta * mat.emission;  // non-zero only on glowing Lambertian surfaces
        if constexpr (!kLambertOnly)
            if (mat.type == MaterialType::pbr)
                radiance += beta * pbr_hit_emission<S>(scene, ray, hit, si, mat, prev);
        if (depth == max_depth) break;

        const Vec3 wo = -ray.dir;
        if constexpr (!kLambertOnly)
            if (wavelength == 0 && disperses(mat)) {
                const PathWavelength w = sample_path_wavelength(sampler.next_1d());
                wavelength = w.nm;
                beta *= w.weight();
            }
        const auto bsdf = make_shading<kLambertOnly>(mat, si, scene.textures, wavelength);
        if constexpr (S != Strategy::none) {
            const float u_select = sampler.next_1d();
            const Vec2 u_light = sampler.next_2d();
            if (!bsdf.is_delta())
                radiance += beta * direct_light<S, kUnlit>(scene, si, bsdf, wo, ray.time, u_select, u_light);
        }
        BsdfSample bs;
        if (!sample_shading(bsdf, wo, sampler, bs)) break;
        beta *= bs.weight;
        eta_scale *= bs.eta_scale;
        if constexpr (!kLambertOnly)
            if (bs.transmit) medium = Medium::after_refraction(mat, si.front_face);
        prev = PrevVertex{si.p, bs.pdf, bs.delta};
        if (depth >= kRouletteStartDepth && !survive_roulette(sampler, beta, eta_scale)) break;
        ray = Ray{offset_ray_origin(si.p, bs.transmit ? -si.ng : si.ng), bs.wi, 0.0f, kInfinity, ray.time};
    }
    return radiance;
}

/// The kernels a scene can get; chosen once per scene from its features.
enum class PathKernel : uint8_t {
    plain_lambert,
    plain,
    plain_unlit,
    delta_lambert,
    delta,
    delta_unlit,
    mis_lambert,
    mis,
    mis_unlit
};

PathKernel choose_kernel(const SceneFeatures& f) {
    // Unlit surfaces make every shadow ray look past them: only scenes with them pay for it.
    if (f.has_area_lights || f.has_envmap)
        return f.lambertian_only ? PathKernel::mis_lambert
               : f.has_unlit     ? PathKernel::mis_unlit
                                 : PathKernel::mis;
    if (f.has_lights)
        return f.lambertian_only ? PathKernel::delta_lambert
               : f.has_unlit     ? PathKernel::delta_unlit
                                 : PathKernel::delta;
    // The plain Lambertian kernel skips emission altogether.
    if (f.lambertian_only && !f.has_emitters) return PathKernel::plain_lambert;
    return f.has_unlit ? PathKernel::plain_unlit : PathKernel::plain;
}

}  // namespace

bool occluded_except_unlit(const Scene& scene, Ray ray, OcclusionCache& cache) {
    if (!scene.occluded(ray, cache)) return false;  // nothing at all in the way: the common answer
    for (int pass = 0; pass <= kMaxUnlitPasses; ++pass) {
        Ray probe = ray;
        Hit hit;
        if (!scene.intersect(probe, hit)) return false;
        if (scene.materials[scene.interact(probe, hit).material].type != MaterialType::unlit) return true;
        ray.tmin = hit.t;  // the next hit beyond this one: (tmin, tmax) is open
    }
    return true;
}

Rgb path_trace_first_hit(const Scene& scene, Ray ray, const Hit* first, Sampler& sampler, int max_depth) {
    switch (choose_kernel(scene.features)) {
        case PathKernel::plain_lambert:
            return path_kernel<Strategy::none, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::plain:
            return path_kernel<Strategy::none, false>(scene, ray, sampler, max_depth, first);
        case PathKernel::plain_unlit:
            return path_kernel<Strategy::none, false, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::delta_lambert:
            return path_kernel<Strategy::delta, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::delta:
            return path_kernel<Strategy::delta, false>(scene, ray, sampler, max_depth, first);
        case PathKernel::delta_unlit:
            return path_kernel<Strategy::delta, false, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::mis_lambert:
            return path_kernel<Strategy::mis, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::mis_unlit:
            return path_kernel<Strategy::mis, false, true>(scene, ray, sampler, max_depth, first);
        case PathKernel::mis:
            break;
    }
    return path_kernel<Strategy::mis, false>(scene, ray, sampler, max_depth, first);
}

Rgb path_trace(const Scene& scene, Ray ray, Sampler& sampler, int max_depth) {
    return path_trace_first_hit(scene, ray, nullptr, sampler, max_depth);
}

Rgb path_trace_with(const Scene& scene, Ray ray, Sampler& sampler, int max_depth, LightStrategy strategy) {
    switch (strategy) {
        case LightStrategy::bsdf_only:
            return path_kernel<Strategy::none, false, true>(scene, ray, sampler, max_depth);
        case LightStrategy::light_only:
            return path_kernel<Strategy::light_only, false, true>(scene, ray, sampler, max_depth);
        case LightStrategy::mis:
            break;
    }
    return path_kernel<Strategy::mis, false, true>(scene, ray, sampler, max_depth);
}

const char* path_kernel_name(const Scene& scene) {
    switch (choose_kernel(scene.features)) {
        case PathKernel::plain_lambert:
            return "path<no light sampling, lambertian only>";
        case PathKernel::plain:
            return "path<no light sampling, all materials>";
        case PathKernel::plain_unlit:
            return "path<no light sampling, all materials, unlit>";
        case PathKernel::delta_lambert:
            return "path<delta lights, lambertian only>";
        case PathKernel::delta:
            return "path<delta lights, all materials>";
        case PathKernel::delta_unlit:
            return "path<delta lights, all materials, unlit>";
        case PathKernel::mis_lambert:
            return "path<MIS, lambertian only>";
        case PathKernel::mis_unlit:
            return "path<MIS, all materials, unlit>";
        case PathKernel::mis:
            break;
    }
    return "path<MIS, all materials>";
}

namespace {

/// The inspection images: first-hit albedo, shading normal, or distance.
Rgb inspect(const Scene& scene, Ray ray) {
    Hit hit;
    const IntegratorType type = scene.render.integrator;
    if (!scene.intersect(ray, hit))
        return type == IntegratorType::albedo ? eval_background(scene.background, ray.dir) : Rgb(0.0f);
    const SurfaceInteraction si = scene.interact(ray, hit);
    if (type == IntegratorType::normals) return (si.ns + Vec3(1.0f)) * 0.5f;
    if (type == IntegratorType::depth) return Rgb(hit.t);
    const MaterialDesc& m = scene.materials[si.material];
    switch (m.type) {
        case MaterialType::dielectric:
            return Rgb(1.0f);
        case MaterialType::emissive:
            return eval_color(m.radiance, scene.textures, si.p, si.uv);
        default:
            return material_albedo(m, si, scene.textures);
    }
}

}  // namespace

Rgb estimate_radiance(const Scene& scene, Ray ray, Sampler& sampler, int max_depth) {
    switch (scene.render.integrator) {
        case IntegratorType::path:
            return path_trace(scene, ray, sampler, max_depth);
        case IntegratorType::whitted:
            return whitted(scene, ray, max_depth);
        case IntegratorType::albedo:
        case IntegratorType::normals:
        case IntegratorType::depth:
            return inspect(scene, ray);
        default:
            return path_trace(scene, ray, sampler, max_depth);
    }
}

}  // namespace sahara
