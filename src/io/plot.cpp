#include "io/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace sahara {

namespace {

/// One 5x7 glyph: 7 rows of 5 bits, bit 4 = leftmost column.
struct Glyph {
    char c;
    std::array<uint8_t, 7> rows;
};

// Drawn for this project; lower case letters map to these upper case shapes.
constexpr Glyph kFont[] = {
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1E, 0x01, 0x01, 0x0E, 0x01, 0x01, 0x1E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}}, {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'/', {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}}, {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
    {'^', {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00}}, {'*', {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}}, {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}},
    {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}}, {'\'', {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
    {'?', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}}, {' ', {0, 0, 0, 0, 0, 0, 0}},
};

const Glyph& glyph(char c) {
    if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
    for (const Glyph& g : kFont)
        if (g.c == c) return g;
    for (const Glyph& g : kFont)
        if (g.c == '?') return g;
    return kFont[0];
}

constexpr int kAdvance = 6;  // font dots per character, spacing included

}  // namespace

Raster::Raster(int w, int h, Rgb fill) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3) {
    for (size_t i = 0; i < rgb.size(); i += 3) {
        rgb[i] = fill.x;
        rgb[i + 1] = fill.y;
        rgb[i + 2] = fill.z;
    }
}

void Raster::set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    float* p = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
    p[0] = c.x;
    p[1] = c.y;
    p[2] = c.z;
}

void Raster::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
        for (int x = std::min(x0, x1); x <= std::max(x0, x1); ++x) set(x, y, c);
}

void Raster::line(double x0, double y0, double x1, double y1, Rgb c, int thickness, int dash) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, int(std::ceil(len * 2)));
    const int r0 = -(thickness - 1) / 2, r1 = thickness / 2;
    for (int i = 0; i <= steps; ++i) {
        const double t = double(i) / steps;
        if (dash > 0 && int(t * len / dash) % 2 == 1) continue;
        const int x = int(std::lround(x0 + (x1 - x0) * t)), y = int(std::lround(y0 + (y1 - y0) * t));
        fill_rect(x + r0, y + r0, x + r1, y + r1, c);
    }
}

void Raster::text(int x, int y, const std::string& s, Rgb c, int scale, bool vertical) {
    for (size_t k = 0; k < s.size(); ++k) {
        const Glyph& g = glyph(s[k]);
        const int offset = int(k) * kAdvance * scale;
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col) {
                if (!(g.rows[size_t(row)] & (0x10 >> col))) continue;
                // Vertical text is the horizontal text rotated 90 degrees anticlockwise.
                const int px = vertical ? x + row * scale : x + offset + col * scale;
                const int py = vertical ? y - offset - col * scale - scale + 1 : y + row * scale;
                fill_rect(px, py, px + scale - 1, py + scale - 1, c);
            }
    }
}

int text_width(const std::string& s, int scale) { return int(s.size()) * kAdvance * scale - scale; }

std::string decade_label(int e) {
    char buf[32];
    if (e >= 0 && e <= 3)
        std::snprintf(buf, sizeof buf, "%.0f", std::pow(10.0, e));
    else if (e < 0 && e >= -3)
        std::snprintf(buf, sizeof buf, "%.*f", -e, std::pow(10.0, e));
    else
        std::snprintf(buf, sizeof buf, "1E%d", e);
    return buf;
}

namespace {

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

struct Frame2 {
    int left, top, right, bottom;  // plot area in pixels
    int x_lo, x_hi, y_lo, y_hi;    // decades
    double px(double v) const { return left + (std::log10(v) - x_lo) / (x_hi - x_lo) * (right - left); }
    double py(double v) const { return bottom - (std::log10(v) - y_lo) / (y_hi - y_lo) * (bottom - top); }
};

/// Label of tick m * 10^e: decades always; 2 and 5 too when the axis spans one decade.
std::string tick_label(int e, int m, int decades) {
    if (m == 1) return decade_label(e);
    if (decades > 1 || (m != 2 && m != 5)) return {};
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", m * std::pow(10.0, e));
    return buf;
}

void draw_axes(Raster& r, const LogLogPlot& plot, const Frame2& f) {
    const Rgb black(0.0f), grid(0.85f), minor_grid(0.94f);
    for (int e = f.x_lo; e <= f.x_hi; ++e)
        for (int m = 1; m <= (e < f.x_hi ? 9 : 1); ++m) {
            const double x = f.px(m * std::pow(10.0, e));
            r.line(x, f.top, x, f.bottom, m == 1 ? grid : minor_grid);
            r.line(x, f.bottom, x, f.bottom + (m == 1 ? 8 : 4), black);
            const std::string label = tick_label(e, m, f.x_hi - f.x_lo);
            if (!label.empty()) r.text(int(x) - text_width(label) / 2, f.bottom + 14, label, black);
        }
    for (int e = f.y_lo; e <= f.y_hi; ++e)
        for (int m = 1; m <= (e < f.y_hi ? 9 : 1); ++m) {
            const double y = f.py(m * std::pow(10.0, e));
            r.line(f.left, y, f.right, y, m == 1 ? grid : minor_grid);
            r.line(f.left - (m == 1 ? 8 : 4), y, f.left, y, black);
            const std::string label = tick_label(e, m, f.y_hi - f.y_lo);
            if (!label.empty()) r.text(f.left - 12 - text_width(label), int(y) - 7, label, black);
        }
    r.line(f.left, f.top, f.left, f.bottom, black, 2);
    r.line(f.left, f.bottom, f.right, f.bottom, black, 2);
    r.text((f.left + f.right - text_width(plot.x_label)) / 2, f.bottom + 42, plot.x_label, black);
    r.text(18, (f.top + f.bottom + text_width(plot.y_label)) / 2, plot.y_label, black, 2, true);
    r.text((f.left + f.right - text_width(plot.title)) / 2, 16, plot.title, black);
}

void draw_legend(Raster& r, const LogLogPlot& plot, const Frame2& f) {
    int w = 0;
    for (const PlotSeries& s : plot.series) w = std::max(w, text_width(s.label));
    // Bottom left: convergence curves fall from the top left to the bottom right.
    const int row = 22, x0 = f.left + 12, x1 = x0 + w + 60, y1 = f.bottom - 12;
    const int y0 = y1 - row * int(plot.series.size()) - 8;
    r.fill_rect(x0, y0, x1, y1, Rgb(1.0f));
    r.line(x0, y0, x1, y0, Rgb(0.0f));
    r.line(x0, y1, x1, y1, Rgb(0.0f));
    r.line(x0, y0, x0, y1, Rgb(0.0f));
    r.line(x1, y0, x1, y1, Rgb(0.0f));
    for (size_t i = 0; i < plot.series.size(); ++i) {
        const PlotSeries& s = plot.series[i];
        const int y = y0 + 15 + row * int(i);
        r.line(x0 + 8, y, x0 + 40, y, s.color, 3, s.dashed ? 6 : 0);
        if (!s.dashed) r.fill_rect(x0 + 21, y - 3, x0 + 27, y + 3, s.color);
        r.text(x0 + 50, y - 7, s.label, Rgb(0.0f));
    }
}

}  // namespace

Raster draw_loglog_plot(const LogLogPlot& plot, int width, int height) {
    Raster r(width, height, Rgb(1.0f));
    Frame2 f{110, 50, width - 30, height - 80, 0, 1, 0, 1};
    decade_range(plot, false, f.x_lo, f.x_hi);
    decade_range(plot, true, f.y_lo, f.y_hi);
    draw_axes(r, plot, f);
    for (const PlotSeries& s : plot.series) {
        bool have_prev = false;
        double px = 0, py = 0;
        for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
            if (!(s.x[i] > 0) || !(s.y[i] > 0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
            const double x = f.px(s.x[i]), y = f.py(s.y[i]);
            if (have_prev) r.line(px, py, x, y, s.color, s.dashed ? 2 : 3, s.dashed ? 8 : 0);
            if (!s.dashed) r.fill_rect(int(x) - 4, int(y) - 4, int(x) + 4, int(y) + 4, s.color);
            px = x;
            py = y;
            have_prev = true;
        }
    }
    draw_legend(r, plot, f);
    return r;
}

}  // namespace sahara
