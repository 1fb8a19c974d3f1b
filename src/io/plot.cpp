#include "io/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "base/error.h"
#include "io/files.h"
#include "io/image_codec.h"

namespace sahara {

namespace fs = std::filesystem;

TickLabel decade_label(int e) {
    // ASCII only: OpenImageIO 2.4's render_text garbles characters outside it,
    // so the exponent is a raised superscript rather than Unicode digits.
    if (e < -3 || e > 3) return {"10", std::to_string(e)};
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", std::max(0, -e), std::pow(10.0, e));
    return {buf, ""};
}

namespace {

constexpr PlotColor kInk{0.13f, 0.13f, 0.13f};
constexpr PlotColor kAxis{0, 0, 0};
constexpr PlotColor kMajorGrid{0.85f, 0.85f, 0.85f};
constexpr PlotColor kMinorGrid{0.94f, 0.94f, 0.94f};
constexpr PlotColor kWhite{1, 1, 1};

/// Decade range [lo, hi] (exponents) covering all positive values of one axis.
void decade_range(const LogLogPlot& plot, bool y_axis, int& lo, int& hi) {
    double mn = INFINITY, mx = -INFINITY;
    for (const PlotSeries& s : plot.series)
        for (double v : y_axis ? s.y : s.x)
            if (v > 0 && std::isfinite(v)) {
                mn = std::min(mn, v);
                mx = std::max(mx, v);
            }
    if (!(mn <= mx)) {
        mn = 1;
        mx = 10;
    }
    lo = int(std::floor(std::log10(mn) + 1e-9));
    hi = int(std::ceil(std::log10(mx) - 1e-9));
    if (hi <= lo) hi = lo + 1;
}

/// The plot area in pixels and the decades it spans on each axis.
struct Frame {
    double left, top, right, bottom;
    int x_lo, x_hi, y_lo, y_hi;
    double px(double v) const { return left + (std::log10(v) - x_lo) / (x_hi - x_lo) * (right - left); }
    double py(double v) const { return bottom - (std::log10(v) - y_lo) / (y_hi - y_lo) * (bottom - top); }
};

/// Label of tick m * 10^e: decades always; 2 and 5 too when the axis spans one
/// decade and the values read as plain decimals.
TickLabel tick_label(int e, int m, int decades) {
    if (m == 1) return decade_label(e);
    if (decades > 1 || (m != 2 && m != 5) || e < -3 || e > 2) return {};
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", m * std::pow(10.0, e));
    return {buf, ""};
}

/// Width of `text` in pixels, estimated: the layout cannot measure the viewer's
/// font, so this errs wide (DejaVu Sans averages about 0.55 em per character).
double estimated_text_width(const std::string& text, double size) {
    size_t chars = 0;
    for (unsigned char c : text) chars += (c & 0xC0) != 0x80;  // UTF-8: count code points
    return 0.62 * size * double(chars);
}

void add_segment(PlotDrawing& d, const std::string& role, PlotPoint a, PlotPoint b, PlotColor color,
                 double width = 1) {
    d.items.emplace_back(PlotPath{role, {a, b}, color, width, 0, {}});
}

void add_text(PlotDrawing& d, const std::string& role, const std::string& text, PlotPoint at, double size,
              TextAnchor anchor, TextBaseline baseline, bool vertical = false) {
    d.items.emplace_back(PlotText{role, text, at, size, kInk, anchor, baseline, vertical, {}});
}

void add_tick_label(PlotDrawing& d, const std::string& role, const TickLabel& label, PlotPoint at,
                    TextAnchor anchor, TextBaseline baseline) {
    d.items.emplace_back(
        PlotText{role, label.text, at, 13, kInk, anchor, baseline, false, label.superscript});
}

/// Grid lines, ticks and tick labels of both axes (m * 10^e for m = 1..9).
void add_ticks(PlotDrawing& d, const Frame& f) {
    for (int e = f.x_lo; e <= f.x_hi; ++e)
        for (int m = 1; m <= (e < f.x_hi ? 9 : 1); ++m) {
            const double x = f.px(m * std::pow(10.0, e));
            const bool major = m == 1;
            add_segment(d, "grid", {x, f.top}, {x, f.bottom}, major ? kMajorGrid : kMinorGrid);
            add_segment(d, "tick", {x, f.bottom}, {x, f.bottom + (major ? 6 : 3)}, kAxis);
            if (const TickLabel label = tick_label(e, m, f.x_hi - f.x_lo); !label.text.empty())
                add_tick_label(d, "tick-x", label, {x, f.bottom + 9}, TextAnchor::middle,
                               TextBaseline::hanging);
        }
    for (int e = f.y_lo; e <= f.y_hi; ++e)
        for (int m = 1; m <= (e < f.y_hi ? 9 : 1); ++m) {
            const double y = f.py(m * std::pow(10.0, e));
            const bool major = m == 1;
            add_segment(d, "grid", {f.left, y}, {f.right, y}, major ? kMajorGrid : kMinorGrid);
            add_segment(d, "tick", {f.left - (major ? 6 : 3), y}, {f.left, y}, kAxis);
            if (const TickLabel label = tick_label(e, m, f.y_hi - f.y_lo); !label.text.empty())
                add_tick_label(d, "tick-y", label, {f.left - 9, y}, TextAnchor::end, TextBaseline::middle);
        }
}

void add_axes_and_labels(PlotDrawing& d, const LogLogPlot& plot, const Frame& f) {
    add_segment(d, "axis", {f.left, f.top}, {f.left, f.bottom}, kAxis, 1.5);
    add_segment(d, "axis", {f.left, f.bottom}, {f.right, f.bottom}, kAxis, 1.5);
    const double mid_x = (f.left + f.right) / 2;
    add_text(d, "axis-label", plot.x_label, {mid_x, double(d.height) - 18}, 15, TextAnchor::middle,
             TextBaseline::alphabetic);
    add_text(d, "axis-label", plot.y_label, {22, (f.top + f.bottom) / 2}, 15, TextAnchor::middle,
             TextBaseline::middle, true);
    add_text(d, "title", plot.title, {mid_x, 30}, 17, TextAnchor::middle, TextBaseline::alphabetic);
}

bool plottable(double x, double y) { return x > 0 && y > 0 && std::isfinite(x) && std::isfinite(y); }

PlotBox marker(PlotPoint at, PlotColor color, std::string title) {
    constexpr double r = 3.5;
    return {"marker", {at.x - r, at.y - r}, {at.x + r, at.y + r}, color, true, std::move(title)};
}

void add_series(PlotDrawing& d, const LogLogPlot& plot, const PlotSeries& s, const Frame& f) {
    PlotPath path{
        s.dashed ? "guide" : "series", {}, s.color, s.dashed ? 1.5 : 2, s.dashed ? 6.0 : 0, s.label};
    std::vector<PlotBox> markers;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        if (!plottable(s.x[i], s.y[i])) continue;
        const PlotPoint p{f.px(s.x[i]), f.py(s.y[i])};
        path.points.push_back(p);
        char title[320];
        std::snprintf(title, sizeof title, "%s: %s %.4g, %s %.4g", s.label.c_str(), plot.x_label.c_str(),
                      s.x[i], plot.y_label.c_str(), s.y[i]);
        if (!s.dashed) markers.push_back(marker(p, s.color, title));
    }
    d.items.emplace_back(std::move(path));
    for (PlotBox& m : markers) d.items.emplace_back(std::move(m));
}

/// The legend, bottom left inside the plot area: convergence curves fall from
/// the top left to the bottom right, so that corner is usually empty.
void add_legend(PlotDrawing& d, const LogLogPlot& plot, const Frame& f) {
    constexpr double kRow = 20, kSize = 13, kSample = 30;
    double text_w = 0;
    for (const PlotSeries& s : plot.series) text_w = std::max(text_w, estimated_text_width(s.label, kSize));
    const double x0 = f.left + 12, x1 = x0 + 10 + kSample + 8 + text_w + 10, y1 = f.bottom - 12;
    const double y0 = y1 - kRow * double(plot.series.size()) - 8;
    d.items.emplace_back(PlotBox{"legend", {x0, y0}, {x1, y1}, kWhite, true, {}});
    d.items.emplace_back(PlotBox{"legend", {x0, y0}, {x1, y1}, kMajorGrid, false, {}});
    for (size_t i = 0; i < plot.series.size(); ++i) {
        const PlotSeries& s = plot.series[i];
        const double y = y0 + 4 + kRow * (double(i) + 0.5);
        d.items.emplace_back(PlotPath{"legend",
                                      {{x0 + 10, y}, {x0 + 10 + kSample, y}},
                                      s.color,
                                      s.dashed ? 1.5 : 2,
                                      s.dashed ? 6.0 : 0,
                                      {}});
        if (!s.dashed) d.items.emplace_back(marker({x0 + 10 + kSample / 2, y}, s.color, {}));
        add_text(d, "legend", s.label, {x0 + 10 + kSample + 8, y}, kSize, TextAnchor::start,
                 TextBaseline::middle);
    }
}

}  // namespace

std::vector<std::string> text_fonts() {
    // DejaVu Sans is Debian's default sans face (fonts-dejavu-core); the others
    // are common substitutes on other systems.
    return {"DejaVuSans", "LiberationSans-Regular", "FreeSans", "Arial"};
}

PlotDrawing layout_loglog_plot(const LogLogPlot& plot, int width, int height) {
    PlotDrawing d;
    d.width = width;
    d.height = height;
    d.fonts = text_fonts();
    d.font_family = "'DejaVu Sans', Verdana, 'Liberation Sans', Arial, sans-serif";
    Frame f{90, 50, double(width) - 30, double(height) - 70, 0, 1, 0, 1};
    decade_range(plot, false, f.x_lo, f.x_hi);
    decade_range(plot, true, f.y_lo, f.y_hi);
    add_ticks(d, f);
    add_axes_and_labels(d, plot, f);
    for (const PlotSeries& s : plot.series) add_series(d, plot, s, f);
    add_legend(d, plot, f);
    return d;
}

namespace {

std::string xml_escaped(const std::string& s) {
    std::string out;
    for (char c : s) switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    return out;
}

std::string hex(PlotColor c) {
    auto byte = [](float v) { return int(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte(c.r), byte(c.g), byte(c.b));
    return buf;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

/// The element's hover text, or "/>" when it has none.
std::string close_with_title(const std::string& tag, const std::string& title) {
    return title.empty() ? "/>\n" : "><title>" + xml_escaped(title) + "</title></" + tag + ">\n";
}

std::string svg_element(const PlotPath& p) {
    std::string points;
    for (const PlotPoint& q : p.points) {
        if (!points.empty()) points += ' ';
        points += num(q.x) + ',' + num(q.y);
    }
    std::string s = "<polyline class=\"" + p.role + "\" points=\"" + points + "\" fill=\"none\" stroke=\"" +
                    hex(p.color) + "\" stroke-width=\"" + num(p.width) + "\" stroke-linejoin=\"round\"";
    if (p.dash > 0) s += " stroke-dasharray=\"" + num(p.dash) + " " + num(p.dash) + "\"";
    return s + close_with_title("polyline", p.title);
}

std::string svg_element(const PlotBox& b) {
    std::string s = "<rect class=\"" + b.role + "\" x=\"" + num(b.min.x) + "\" y=\"" + num(b.min.y) +
                    "\" width=\"" + num(b.max.x - b.min.x) + "\" height=\"" + num(b.max.y - b.min.y) + "\"";
    s += b.filled ? " fill=\"" + hex(b.color) + "\"" : " fill=\"none\" stroke=\"" + hex(b.color) + "\"";
    return s + close_with_title("rect", b.title);
}

std::string svg_element(const PlotText& t) {
    static const char* const kAnchor[] = {"start", "middle", "end"};
    // A shift from the alphabetic baseline rather than dominant-baseline, which
    // several SVG renderers ignore; fractions of an em fitting DejaVu Sans.
    static const char* const kBaselineShift[] = {"0", "0.35em", "0.75em"};
    std::string s = "<text class=\"" + t.role + "\" x=\"" + num(t.at.x) + "\" y=\"" + num(t.at.y) +
                    "\" font-size=\"" + num(t.size) + "\" fill=\"" + hex(t.color) + "\" text-anchor=\"" +
                    kAnchor[int(t.anchor)] + "\" dy=\"" + kBaselineShift[int(t.baseline)] + "\"";
    if (t.vertical) s += " transform=\"rotate(-90 " + num(t.at.x) + " " + num(t.at.y) + ")\"";
    s += ">" + xml_escaped(t.text);
    if (!t.superscript.empty())
        s += "<tspan font-size=\"" + num(superscript_size(t.size)) + "\" dy=\"" +
             num(-superscript_rise(t.size)) + "\">" + xml_escaped(t.superscript) + "</tspan>";
    return s + "</text>\n";
}

}  // namespace

std::string plot_svg(const PlotDrawing& d) {
    const std::string w = std::to_string(d.width), h = std::to_string(d.height);
    std::string s =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
        w + "\" height=\"" + h + "\" viewBox=\"0 0 " + w + " " + h + "\" font-family=\"" +
        xml_escaped(d.font_family) + "\">\n";
    s += "<rect class=\"background\" width=\"" + w + "\" height=\"" + h + "\" fill=\"" + hex(d.background) +
         "\"/>\n";
    for (const PlotItem& item : d.items) s += std::visit([](const auto& e) { return svg_element(e); }, item);
    return s + "</svg>\n";
}

void write_plot_svg(const std::string& file, const PlotDrawing& drawing) {
    write_via_temporary(
        file,
        [&](const fs::path& tmp) {
            std::ofstream out(tmp, std::ios::binary);
            out << plot_svg(drawing);
            return out.flush() ? std::string() : "cannot write the file";
        },
        "plot");
}

std::string write_plot_png(const std::string& file, const PlotDrawing& drawing) {
    const ImageCodecApi& codec = image_codec(file);
    std::string warning;
    write_via_temporary(
        file, [&](const fs::path& tmp) { return codec.draw_plot(tmp.string(), drawing, warning); }, "plot");
    return warning;
}

std::string draw_texts(int width, int height, std::vector<float>& rgb, const std::vector<PlotText>& texts,
                       const std::string& file_for_errors) {
    if (rgb.size() != size_t(width) * size_t(height) * 3)
        throw input_error(file_for_errors, "", "the pixels do not match the image size");
    const ImageCodecApi& codec = image_codec(file_for_errors);
    std::string warning;
    if (const std::string why = codec.draw_texts(width, height, rgb.data(), texts, text_fonts(), warning);
        !why.empty())
        throw input_error(file_for_errors, "", why);
    return warning;
}

}  // namespace sahara
