// The bvh-cost legend's labels: render leaves them as text to draw, app draws
// them with a TrueType font through the image codec.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "app/render_file.h"
#include "io/scene_parser.h"
#include "render/bvh_cost.h"

using namespace sahara;

namespace {

/// Pixels of rows [y0, y1) darker than the legend's colours and its white ground.
int dark_pixels(const BvhCostImage& img, int y0, int y1, int x0, int x1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const float* p = &img.rgb[(size_t(y) * size_t(img.width) + size_t(x)) * 3];
            n += p[0] < 0.4f && p[1] < 0.4f && p[2] < 0.4f;
        }
    return n;
}

}  // namespace

TEST_CASE("bvh-cost legend: the labels are drawn under the bar and the heat map stays as it was") {
    const Scene scene = build_scene(default_scene());
    const int width = 160, height = 120;
    const BvhCostImage plain = render_bvh_cost(scene, width, height, 1);
    REQUIRE(plain.labels.size() == 2);
    CHECK(plain.labels[0].text == "0");
    CHECK(plain.labels[1].text.rfind(std::to_string(std::lround(plain.max_cost)) + " ", 0) == 0);
    CHECK(plain.labels[1].right_aligned);
    const int text_top = plain.labels[0].y;
    CHECK(text_top > height);
    CHECK(text_top < plain.height);
    // Without the labels drawn, the strip under the bar is white.
    CHECK(dark_pixels(plain, text_top, plain.height, 0, width) == 0);

    BvhCostImage drawn = plain;
    const std::string warning = draw_bvh_cost_legend(drawn, "legend.png");
    REQUIRE(drawn.rgb.size() == plain.rgb.size());
    // The picture and the colour bar above the labels are untouched.
    const size_t above = size_t(text_top - 2) * size_t(width) * 3;
    CHECK(std::equal(plain.rgb.begin(), plain.rgb.begin() + std::ptrdiff_t(above), drawn.rgb.begin()));
    if (std::filesystem::exists("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")) CHECK(warning.empty());
    if (!warning.empty()) {
        MESSAGE("no font: " << warning);
        CHECK(drawn.rgb == plain.rgb);
        return;
    }
    // "0" at the left end, the maximum at the right end, nothing between them.
    CHECK(dark_pixels(drawn, text_top - 2, drawn.height, 0, 24) > 10);
    CHECK(dark_pixels(drawn, text_top - 2, drawn.height, width / 2, width) > 100);
    CHECK(dark_pixels(drawn, text_top - 2, drawn.height, 24, 40) == 0);
    CHECK(drawn.rgb != plain.rgb);
}

TEST_CASE("bvh-cost images of every small width have a legend and no crash") {
    const Scene scene = build_scene(default_scene());
    CHECK(heat_color(std::nanf("")) == heat_color(0.0f));
    for (int width = 1; width <= 20; ++width) {
        CAPTURE(width);
        BvhCostImage img = render_bvh_cost(scene, width, 3, 1);
        CHECK(img.width == width);
        CHECK(img.rgb.size() == size_t(img.width) * size_t(img.height) * 3);
        for (float v : img.rgb) REQUIRE(std::isfinite(v));
        draw_bvh_cost_legend(img, "small.png");  // labels reaching past the edge are clipped
    }
}
