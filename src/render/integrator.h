#pragma once
/// Integrators: estimate the radiance arriving along a camera ray.
#include "render/sampler.h"
#include "scene/scene.h"

namespace sahara {

/// Radiance along `ray` (unit direction, as the camera makes them) with the
/// scene's integrator (scene.render.integrator) and at most `max_depth` rays
/// per path, the camera ray included.
Rgb estimate_radiance(const Scene& scene, Ray ray, Sampler& sampler, int max_depth);

/// Unidirectional path tracing: BSDF sampling, next-event estimation of lights
/// and emitters combined by MIS, unbiased Russian roulette after a few bounces.
/// Runs the kernel specialised for the scene's features (see path_kernel_name).
Rgb path_trace(const Scene& scene, Ray ray, Sampler& sampler, int max_depth);

/// path_trace() whose camera ray was already traced (in a packet): `first` is
/// its Scene::intersect answer (a miss when !first->hit()); nullptr traces it here.
Rgb path_trace_first_hit(const Scene& scene, Ray ray, const Hit* first, Sampler& sampler, int max_depth);
/// How path tracing gathers light from sampled emitters (for tests comparing strategies).
enum class LightStrategy : uint8_t {
    mis,         ///< light sampling and BSDF sampling, power heuristic
    bsdf_only,   ///< no light sampling: emitters count only when a path hits them
    light_only,  ///< light sampling only: hits of light-sampled emitters after a diffuse bounce are ignored
};

/// Path tracing with the general kernel (all materials) and a given strategy.
Rgb path_trace_with(const Scene& scene, Ray ray, Sampler& sampler, int max_depth, LightStrategy strategy);

/// The classic Whitted ray tracer: ambient = albedo * background radiance in
/// the shading-normal direction, point and directional lights with hard
/// shadows, perfect mirrors and Fresnel-weighted reflection + refraction.
Rgb whitted(const Scene& scene, Ray ray, int max_depth);

/// Scene::occluded for a scene with unlit materials: whether anything but
/// unlit surfaces (which only camera rays see) blocks the ray.
bool occluded_except_unlit(const Scene& scene, Ray ray, OcclusionCache& cache);

/// Name of the path-tracing kernel chosen for the scene's features.
const char* path_kernel_name(const Scene& scene);

}  // namespace sahara
