#include "render/bvh_cost.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "render/camera.h"

namespace sahara {

namespace {

/// Height of the legend strip in pixels (bar + labels).
constexpr int kLegendHeight = 44;
/// Font size of the legend's labels in pixels (they sit under the bar).
constexpr int kLabelSize = 14;

}  // namespace

Rgb heat_color(float t) {
    t = t > 0.0f ? std::min(t, 1.0f) : 0.0f;  // NaN too: it would index outside the stops
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

double bvh_ray_cost(const Scene& scene, const Ray& ray) { return double(scene.traversal_steps(ray)); }

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

    out.rgb.assign(size_t(width) * size_t(height + kLegendHeight) * 3, 1.0f);  // white
    auto set = [&](int x, int y, Rgb c) {
        float* p = &out.rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
        p[0] = c.x, p[1] = c.y, p[2] = c.z;
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            set(x, y, heat_color(float(cost[size_t(y) * size_t(width) + size_t(x)] * scale)));
    // Legend: the colour bar from 0 to the maximum cost, with its end values.
    const int bar_x0 = 8, bar_x1 = std::max(bar_x0 + 1, width - 8), bar_y0 = height + 6, bar_y1 = height + 20;
    // Columns bar_x0..bar_x1 and rows bar_y0..bar_y1, both ends included; the
    // last column repeats the colour of the one before it.
    for (int x = bar_x0; x <= std::min(bar_x1, width - 1); ++x) {
        // An image under 18 pixels wide has a one-column bar: no 0/0 there.
        const Rgb c =
            heat_color(float(std::min(x, bar_x1 - 1) - bar_x0) / float(std::max(1, bar_x1 - bar_x0 - 1)));
        for (int y = bar_y0; y <= bar_y1; ++y) set(x, y, c);
    }
    out.labels.push_back({"0", bar_x0, bar_y1 + 4, kLabelSize, false});
    out.labels.push_back(
        {std::to_string(std::lround(out.max_cost)) + " nodes+prims", bar_x1, bar_y1 + 4, kLabelSize, true});
    out.width = width;
    out.height = height + kLegendHeight;
    return out;
}

}  // namespace sahara
