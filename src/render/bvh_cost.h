#pragma once
/// The `bvh-cost` inspection image: a heat map of the traversal work of each
/// pixel's primary ray (BVH nodes visited + primitives tested), with a colour
/// legend drawn under the picture.
#include <vector>

#include "scene/scene.h"

namespace sahara {

struct BvhCostImage {
    int width = 0, height = 0;  ///< of the whole image, legend included
    std::vector<float> rgb;     ///< linear RGB, row 0 at the top (already display-ready)
    double mean_cost = 0;       ///< mean nodes + primitives per primary ray
    double max_cost = 0;
};

/// Cost of one ray: nodes visited plus primitives tested.
double bvh_ray_cost(const Scene& scene, const Ray& ray);

/// Traces one primary ray through each pixel centre of a width x height image
/// and returns the heat map with a legend strip appended at the bottom.
BvhCostImage render_bvh_cost(const Scene& scene, int width, int height, int threads);

/// The heat-map colour for t in [0, 1]: dark blue -> cyan -> yellow -> red.
Rgb heat_color(float t);

}  // namespace sahara
