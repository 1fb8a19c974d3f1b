/// The Whitted integrator (Whitted 1980, "An Improved Illumination Model for
/// Shaded Display"): deterministic, one ray per branch, a fast preview.
#include "geometry/spawn.h"
#include "render/background.h"
#include "render/bsdf.h"
#include "render/bsdf_layers.h"
#include "render/bsdf_pbr.h"
#include "render/integrator.h"
#include "render/lights.h"
#include "scene/texture.h"

namespace sahara {

namespace {

/// Branches whose weight on the pixel falls below this are not traced: glass
/// would otherwise double the ray count at every level of recursion.
constexpr float kMinBranchWeight = 1e-4f;

/// Lambert shading from point and directional lights, with hard shadows.
Rgb direct_lights(const Scene& scene, const SurfaceInteraction& si, const Rgb& albedo, float time) {
    Rgb sum(0.0f);
    for (uint32_t light = 0; light < scene.lights.size(); ++light) {
        const LightDesc& l = scene.lights[light];
        Vec3 wi;
        Rgb e;
        float tmax = kInfinity;
        if (l.type == LightDesc::Type::point) {
            const Vec3 d = l.position - si.p;
            const float dist2 = length_squared(d);
            if (!(dist2 > 0)) continue;
            const float dist = std::sqrt(dist2);
            wi = d / dist;
            e = l.intensity / dist2;  // inverse-square law
            tmax = dist * (1.0f - 1e-4f);
        } else {
            wi = -normalize(l.direction);
            e = l.irradiance;
        }
        const float cos = dot(wi, si.ns);
        if (cos <= 0 || dot(wi, si.ng) <= 0) continue;
        const Ray shadow{offset_ray_origin(si.p, si.ng), wi, 0.0f, tmax, time};
        if (scene.features.has_unlit ? occluded_except_unlit(scene, shadow, shadow_cache(light))
                                     : scene.occluded(shadow, shadow_cache(light)))
            continue;
        sum += e * cos;
    }
    return albedo * sum * kInvPi;
}

Rgb trace(const Scene& scene, Ray ray, int depth, int max_depth, float weight);

/// Continues along a reflected or refracted direction if the branch still matters.
Rgb branch(const Scene& scene, const SurfaceInteraction& si, const Vec3& dir, bool transmit, float time,
           int depth, int max_depth, float weight) {
    if (weight < kMinBranchWeight) return Rgb(0.0f);
    const Ray next{offset_ray_origin(si.p, transmit ? -si.ng : si.ng), dir, 0.0f, kInfinity, time};
    return trace(scene, next, depth + 1, max_depth, weight);
}

/// The glTF material as a preview: its diffuse base lit like Lambert, plus a
/// mirror reflection weighted by the specular colour (roughness ignored). The
/// layers weigh as in the path tracer (bsdf_layers.h): the base scaled by what
/// they let through, the sheen a diffuse term of its albedo, the clearcoat a
/// mirror about the coat's normal weighted by clearcoat x F.
Rgb whitted_pbr(const Scene& scene, const SurfaceInteraction& si, const MaterialDesc& m, const Vec3& wo,
                float time, int depth, int max_depth, float weight) {
    const Bsdf b = make_bsdf(m, si, scene.textures);
    const LayerWeights layers = b.layers.on ? pbr_layer_weights(b, b.frame.to_local(wo)) : LayerWeights{};
    const Rgb diffuse =
        b.albedo * ((1.0f - b.metallic) * layers.base_scale) + b.layers.sheen * layers.sheen_albedo;
    Rgb radiance =
        diffuse * eval_background(scene.background, si.ns) + direct_lights(scene, si, diffuse, time);
    const auto mirror = [&](const Vec3& n, const Rgb& f) {
        const Vec3 wr = reflect(wo, n);
        if (dot(wr, si.ng) > 0)
            radiance += f * branch(scene, si, wr, false, time, depth, max_depth, weight * max_component(f));
    };
    mirror(si.ns, pbr_fresnel(b, dot(wo, si.ns)) * layers.base_scale);
    if (layers.coat_fresnel > 0)
        mirror(b.layers.coat_frame ? b.frame.to_world(b.layers.coat_normal) : b.frame.n,
               Rgb(layers.coat_fresnel));
    return radiance;
}

/// The first hit that counts for a ray of recursion level `depth`: unlit
/// surfaces show their colour to camera rays and let all other rays pass, as in the path tracer.
bool first_hit(const Scene& scene, Ray& ray, int depth, Hit& hit, SurfaceInteraction& si) {
    for (int pass = 0; pass <= 64; ++pass) {
        if (!scene.intersect(ray, hit)) return false;
        si = scene.interact(ray, hit);
        if (depth == 1 || scene.materials[si.material].type != MaterialType::unlit) return true;
        ray.tmin = hit.t;
        ray.tmax = kInfinity;
    }
    return false;
}

Rgb trace(const Scene& scene, Ray ray, int depth, int max_depth, float weight) {
    Hit hit;
    SurfaceInteraction si;
    if (!first_hit(scene, ray, depth, hit, si)) return eval_background(scene.background, ray.dir);
    const MaterialDesc& m = scene.materials[si.material];
    if (m.type == MaterialType::unlit) return material_albedo(m, si, scene.textures);
    if (m.type == MaterialType::emissive)
        return si.front_face ? eval_color(m.radiance, scene.textures, si.p, si.uv) : Rgb(0.0f);
    Rgb radiance = m.type == MaterialType::lambertian ? m.emission
                   : m.type == MaterialType::pbr      ? pbr_emission(m, si, scene.textures, -ray.dir)
                                                      : Rgb(0.0f);
    if (depth >= max_depth) return radiance;  // the next ray (shadow or secondary) would exceed max_depth
    const Vec3 wo = -ray.dir;
    switch (m.type) {
        case MaterialType::pbr:
            radiance += whitted_pbr(scene, si, m, wo, ray.time, depth, max_depth, weight);
            break;
        case MaterialType::lambertian: {
            const Rgb albedo = material_albedo(m, si, scene.textures);
            radiance += albedo * eval_background(scene.background, si.ns);  // ambient
            radiance += direct_lights(scene, si, albedo, ray.time);
            break;
        }
        case MaterialType::metal: {  // roughness ignored: a perfect mirror
            const Rgb f = fresnel_schlick(material_albedo(m, si, scene.textures), dot(wo, si.ns));
            const Vec3 wr = reflect(wo, si.ns);
            if (dot(wr, si.ng) > 0)
                radiance +=
                    f * branch(scene, si, wr, false, ray.time, depth, max_depth, weight * max_component(f));
            break;
        }
        case MaterialType::dielectric: {
            const float eta = si.front_face ? m.ior : 1.0f / m.ior;
            const float r = fresnel_dielectric(dot(wo, si.ns), eta);
            const Vec3 wr = reflect(wo, si.ns);
            if (dot(wr, si.ng) > 0)
                radiance += r * branch(scene, si, wr, false, ray.time, depth, max_depth, weight * r);
            Vec3 wt;
            if (r < 1.0f && refract(wo, si.ns, eta, &wt) && dot(wt, si.ng) < 0) {
                const float t = (1.0f - r) / (eta * eta);  // radiance compression across the interface
                radiance += t * branch(scene, si, wt, true, ray.time, depth, max_depth, weight * (1.0f - r));
            }
            break;
        }
        case MaterialType::emissive:
        case MaterialType::unlit:
            break;
    }
    return radiance;
}

}  // namespace

Rgb whitted(const Scene& scene, Ray ray, int max_depth) {
    ray.dir = normalize(ray.dir);
    return trace(scene, ray, 1, max_depth, 1.0f);
}

}  // namespace sahara
