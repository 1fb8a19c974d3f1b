#pragma once
/// Integrators: estimate the radiance arriving along a camera ray.
#include "render/sampler.h"
#include "scene/scene.h"

namespace sahara {

/// Radiance along `ray` with the scene's integrator (scene.render.integrator)
/// and at most `max_depth` rays per path, the camera ray included.
Rgb estimate_radiance(const Scene& scene, Ray ray, Sampler& sampler, int max_depth);

/// Unidirectional path tracing with cosine-weighted Lambertian sampling and
/// unbiased Russian roulette after a few bounces.
Rgb path_trace(const Scene& scene, Ray ray, Sampler& sampler, int max_depth);

}  // namespace sahara
