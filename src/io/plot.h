#pragma once
/// A log-log line plot, laid out once in pixels as a plain list of shapes and
/// texts (PlotDrawing), then written as SVG (here) or drawn into a PNG by the
/// image codec plugin (OpenImageIO's line, box and TrueType text renderers).
/// The drawing types use the standard library only, so the plugin can read them.
#include <string>
#include <variant>
#include <vector>

#include "math/vec3.h"

namespace sahara {

/// A display colour: sRGB-encoded values in [0, 1], as stored in the PNG.
struct PlotColor {
    float r = 0, g = 0, b = 0;
};

/// A position in pixels: origin at the top-left corner, y pointing down.
struct PlotPoint {
    double x = 0, y = 0;
};

/// A polyline (two points: a segment). `role` names what it is ("grid",
/// "axis", "tick", "series", "guide", "legend"); SVG keeps it as the class.
struct PlotPath {
    std::string role;
    std::vector<PlotPoint> points;
    PlotColor color;
    double width = 1;
    double dash = 0;    ///< > 0: dashes and gaps of this many pixels
    std::string title;  ///< shown on hover in a browser (SVG only)
};

/// An axis-aligned rectangle, filled or outlined.
struct PlotBox {
    std::string role;
    PlotPoint min, max;
    PlotColor color;
    bool filled = true;
    std::string title;  ///< shown on hover in a browser (SVG only)
};

enum class TextAnchor { start, middle, end };             ///< which end of the text sits at `at.x`
enum class TextBaseline { alphabetic, middle, hanging };  ///< what sits at `at.y`

/// One line of UTF-8 text; vertical text reads bottom to top, turned about `at`.
struct PlotText {
    std::string role;
    std::string text;
    PlotPoint at;
    double size = 14;  ///< font size in pixels
    PlotColor color;
    TextAnchor anchor = TextAnchor::start;
    TextBaseline baseline = TextBaseline::alphabetic;
    bool vertical = false;
    std::string superscript;  ///< drawn right after `text`, smaller and raised (an exponent)
};

/// Font size and rise of a superscript on text of font size `size`.
inline double superscript_size(double size) { return 0.7 * size; }
inline double superscript_rise(double size) { return 0.4 * size; }

using PlotItem = std::variant<PlotPath, PlotBox, PlotText>;

/// Everything a plot shows, in drawing order (later items cover earlier ones).
struct PlotDrawing {
    int width = 0, height = 0;
    PlotColor background{1, 1, 1};
    /// TrueType fonts for the PNG, by name or path, the first one found is used.
    std::vector<std::string> fonts;
    /// The same faces for SVG viewers (CSS font-family list).
    std::string font_family;
    std::vector<PlotItem> items;
};

struct PlotSeries {
    std::string label;
    std::vector<double> x, y;  ///< both > 0 (other points are skipped)
    PlotColor color;
    bool dashed = false;  ///< a guide: dashed, no markers
};

struct LogLogPlot {
    std::string title, x_label, y_label;
    std::vector<PlotSeries> series;
};

/// Lays the plot out on a width x height canvas: decade and minor ticks with
/// grid lines, tick labels, axis labels, title, series, and a legend.
PlotDrawing layout_loglog_plot(const LogLogPlot& plot, int width = 900, int height = 600);

/// The drawing as a standalone SVG document.
std::string plot_svg(const PlotDrawing& drawing);

/// Writes plot_svg(drawing) to `file`. Throws InputError.
void write_plot_svg(const std::string& file, const PlotDrawing& drawing);

/// Draws `drawing` into a PNG through the image codec. Returns a warning (empty:
/// none), e.g. that no font was found and the PNG has no text. Throws InputError.
std::string write_plot_png(const std::string& file, const PlotDrawing& drawing);

/// TrueType fonts for texts in images, by name or path, the first one found is used.
std::vector<std::string> text_fonts();

/// Draws horizontal `texts` (no superscripts) over width x height linear RGB
/// pixels (row 0 at the top) through the image codec, at their own size.
/// Returns a warning (empty: none), e.g. that no font was found and the pixels
/// are unchanged. Throws InputError naming `file_for_errors` if the codec
/// cannot be loaded or the text cannot be drawn.
std::string draw_texts(int width, int height, std::vector<float>& rgb, const std::vector<PlotText>& texts,
                       const std::string& file_for_errors);

/// A tick label: `text`, then `superscript` as an exponent ("10" "-5": 10^-5).
struct TickLabel {
    std::string text, superscript;
};

/// Tick label of 10^e: decimal for -3 <= e <= 3 ("0.01", "100"), else a power of ten.
TickLabel decade_label(int e);

}  // namespace sahara
