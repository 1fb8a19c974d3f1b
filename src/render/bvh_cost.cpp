#include "render/bvh_cost.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/accelerator.h"
#include "render/camera.h"
#include "render/raster.h"

namespace sahara {

namespace {

/// Height of the legend strip in pixels (bar + labels).
constexpr int kLegendHeight = 44;

}  // namespace

Rgb heat_color(float t) {
    t = std::clamp(t, 0.0f, 1.0f);
    // Piecewise-linear ramp through perceptually ordered stops (linear RGB).
    static const Rgb stops[] = {{0.00f, 0.00f, 0.15f},
                                {0.00f, 0.25f, 0.80f},
                                {0.00f, 0.80f, 0.80f},
                                {0.95f, 0.90f, 0.10f},
                                {0.90f, 0.10f, 0.05f}};
    const float x = t * 4.0f;
    const int i = std::min(3, int(x));
    return lerp(x - float(i), stops[i], stops[i + 1]);
}

double bvh_ray_cost(const Scene& scene, const Ray& ray) {
    const Accelerator* accel = scene.accelerator();
    if (!accel) return 0;
    TraversalCounters c;
    Ray r = ray;
    Hit hit;
    accel->intersect_counted(r, hit, c);
    return double(c.nodes_visited + c.prims_tested);
}

BvhCostImage render_bvh_cost(const Scene& scene, int width, int height, int threads) {
    const Camera camera(scene.camera, width, height);
    std::vector<double> cost(size_t(width) * size_t(height));
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads)
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            cost[size_t(y) * size_t(width) + size_t(x)] = bvh_ray_cost(
                scene, camera.generate_ray(float(x) + 0.5f, float(y) + 0.5f, {0.5f, 0.5f}, 0.5f));

    BvhCostImage out;
    double sum = 0;
    for (double c : cost) {
        sum += c;
        out.max_cost = std::max(out.max_cost, c);
    }
    out.mean_cost = cost.empty() ? 0 : sum / double(cost.size());
    const double scale = out.max_cost > 0 ? 1.0 / out.max_cost : 0.0;

    Raster r(width, height + kLegendHeight, Rgb(1.0f));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            r.set(x, y, heat_color(float(cost[size_t(y) * size_t(width) + size_t(x)] * scale)));
    // Legend: the colour bar from 0 to the maximum cost, with its end values.
    const int bar_x0 = 8, bar_x1 = std::max(bar_x0 + 1, width - 8), bar_y0 = height + 6, bar_y1 = height + 20;
    for (int x = bar_x0; x < bar_x1; ++x)
        r.fill_rect(x, bar_y0, x + 1, bar_y1, heat_color(float(x - bar_x0) / float(bar_x1 - bar_x0 - 1)));
    const Rgb ink(0.0f);
    r.text(bar_x0, bar_y1 + 4, "0", ink, 2);
    const std::string max_label = std::to_string(int(std::lround(out.max_cost))) + " NODES+PRIMS";
    r.text(std::max(bar_x0, bar_x1 - text_width(max_label, 2)), bar_y1 + 4, max_label, ink, 2);
    out.width = width;
    out.height = height + kLegendHeight;
    out.rgb = std::move(r.rgb);
    return out;
}

}  // namespace sahara
