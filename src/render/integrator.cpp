#include "render/integrator.h"

#include "geometry/spawn.h"
#include "math/sampling.h"
#include "render/background.h"
#include "render/texture.h"

namespace sahara {

namespace {

/// Paths shorter than this never face Russian roulette.
constexpr int kRouletteStartDepth = 4;

}  // namespace

Rgb path_trace(const Scene& scene, Ray ray, Sampler& sampler, int max_depth) {
    Rgb radiance(0.0f), throughput(1.0f);
    for (int depth = 1; depth <= max_depth; ++depth) {
        Hit hit;
        if (!scene.intersect(ray, hit)) {
            radiance += throughput * eval_background(scene.background, ray.dir);
            break;
        }
        const SurfaceInteraction si = scene.interact(ray, hit);
        const MaterialDesc& mat = scene.materials[si.material];
        if (mat.type == MaterialType::emissive) {
            if (si.front_face) radiance += throughput * eval_color(mat.radiance, scene.textures, si.p, si.uv);
            break;
        }
        if (depth == max_depth) break;
        const Vec3 wi = Frame(si.ns).to_world(sample_cosine_hemisphere(sampler.next_2d()));
        if (dot(wi, si.ng) <= 0.0f) break;  // below the geometric surface: absorbed
        throughput *= eval_color(mat.albedo, scene.textures, si.p, si.uv);
        if (depth >= kRouletteStartDepth) {
            const float survive = std::min(1.0f, max_component(throughput));
            if (sampler.next_1d() >= survive) break;
            throughput /= survive;
        }
        ray = Ray{offset_ray_origin(si.p, si.ng), wi, 0.0f, kInfinity, ray.time};
    }
    return radiance;
}

Rgb estimate_radiance(const Scene& scene, Ray ray, Sampler& sampler, int max_depth) {
    switch (scene.render.integrator) {
        case IntegratorType::path: return path_trace(scene, ray, sampler, max_depth);
        case IntegratorType::albedo:
        case IntegratorType::normals:
        case IntegratorType::depth: {
            Hit hit;
            if (!scene.intersect(ray, hit)) return scene.render.integrator == IntegratorType::albedo
                                                      ? eval_background(scene.background, ray.dir)
                                                      : Rgb(0.0f);
            const SurfaceInteraction si = scene.interact(ray, hit);
            if (scene.render.integrator == IntegratorType::normals) return (si.ns + Vec3(1.0f)) * 0.5f;
            if (scene.render.integrator == IntegratorType::depth) return Rgb(hit.t);
            return eval_color(scene.materials[si.material].albedo, scene.textures, si.p, si.uv);
        }
        default: return path_trace(scene, ray, sampler, max_depth);
    }
}

}  // namespace sahara
