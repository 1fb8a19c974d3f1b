#pragma once
/// A small log-log line plot rasterised into an RGB image: axes with decade
/// ticks and values, axis labels, a title, a legend, solid series with point
/// markers and dashed guide lines. Text uses a built-in 5x7 bitmap font (upper
/// case, digits and common punctuation; lower case is drawn as upper case).
#include <string>
#include <vector>

#include "math/vec3.h"

namespace sahara {

struct PlotSeries {
    std::string label;
    std::vector<double> x, y;  ///< both > 0 (non-positive points are skipped)
    Rgb color{0, 0, 0};
    bool dashed = false;  ///< guides: no markers, dashed line
};

struct LogLogPlot {
    std::string title, x_label, y_label;
    std::vector<PlotSeries> series;
};

/// A linear RGB raster, row 0 at the top (what write_image takes).
struct Raster {
    int width = 0, height = 0;
    std::vector<float> rgb;
    Raster(int w, int h, Rgb fill);
    void set(int x, int y, Rgb c);
    /// A line of the given thickness; dash > 0 draws dash-pixel on/off segments.
    void line(double x0, double y0, double x1, double y1, Rgb c, int thickness = 1, int dash = 0);
    void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
    /// Draws text with its top-left corner at (x, y); `scale` pixels per font dot;
    /// vertical text runs bottom to top with (x, y) its bottom-left corner.
    void text(int x, int y, const std::string& s, Rgb c, int scale = 2, bool vertical = false);
};

/// Width in pixels of `s` drawn at `scale`.
int text_width(const std::string& s, int scale = 2);

/// Rasterises the plot into a width x height image.
Raster draw_loglog_plot(const LogLogPlot& plot, int width = 900, int height = 650);

/// Tick label for 10^e: plain for -3 <= e <= 3 ("0.01", "100"), else "1E-5".
std::string decade_label(int e);

}  // namespace sahara
