#pragma once
/// The `bvh-cost` inspection image: a heat map of the traversal work of each
/// pixel's primary ray (BVH nodes visited + primitives tested), with a colour
/// legend drawn under the picture.
#include <string>
#include <vector>

#include "scene/scene.h"

namespace sahara {

/// A text of the legend. render draws no text (it would need a font, and
/// fonts are io's business): the layer that writes the image draws these
/// (draw_bvh_cost_legend in app/render_file.h).
struct LegendLabel {
    std::string text;
    int x = 0, y = 0;  ///< pixels: the text's top, and its left end (right end if right_aligned)
    int size = 14;     ///< font size in pixels
    bool right_aligned = false;
};

struct BvhCostImage {
    int width = 0, height = 0;        ///< of the whole image, legend included
    std::vector<float> rgb;           ///< linear RGB, row 0 at the top (already display-ready)
    std::vector<LegendLabel> labels;  ///< black text to draw over the legend strip
    double mean_cost = 0;             ///< mean nodes + primitives per primary ray
    double max_cost = 0;
};

/// Cost of one ray: nodes visited plus primitives tested.
double bvh_ray_cost(const Scene& scene, const Ray& ray);

/// Traces one primary ray through each pixel centre of a width x height image
/// and returns the heat map with a legend strip appended at the bottom: the
/// colour bar, and the labels of its ends still to be drawn.
BvhCostImage render_bvh_cost(const Scene& scene, int width, int height, int threads);

/// The heat-map colour for t in [0, 1]: dark blue -> cyan -> yellow -> red.
Rgb heat_color(float t);

}  // namespace sahara
