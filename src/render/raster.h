#pragma once
/// A small RGB canvas with a 5x7 bitmap font, for the legend of the bvh-cost
/// heat map (render/bvh_cost.cpp). Plots are drawn by the image codec instead
/// (io/plot.h).
#include <string>
#include <vector>

#include "math/vec3.h"

namespace sahara {

/// A linear RGB raster, row 0 at the top (what write_image takes).
struct Raster {
    int width = 0, height = 0;
    std::vector<float> rgb;
    Raster(int w, int h, Rgb fill);
    void set(int x, int y, Rgb c);
    void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
    /// Draws text in the 5x7 bitmap font with its top-left corner at (x, y);
    /// `scale` pixels per font dot.
    void text(int x, int y, const std::string& s, Rgb c, int scale = 2);
};

/// Width in pixels of `s` drawn by Raster::text at `scale`.
int text_width(const std::string& s, int scale = 2);

}  // namespace sahara
