// The image codec plugin (see image_codec.h): OpenImageIO behind plain
// functions that return an error message instead of throwing.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <variant>

#include "base/text.h"
#include "io/image_codec.h"
#include "io/plot.h"

namespace sahara {
namespace {

namespace OIIO = OIIO_NAMESPACE;

OIIO::TypeDesc type_desc(ChannelType t) {
    switch (t) {
        case ChannelType::u8:
            return OIIO::TypeDesc::UINT8;
        case ChannelType::u32:
            return OIIO::TypeDesc::UINT32;
        default:
            return OIIO::TypeDesc::FLOAT;
    }
}

std::string decode(const std::string& name, const unsigned char* by_memory, size_t size, int max_side,
                   int max_channels, DecodedPixels& out) try {
    std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
    std::unique_ptr<OIIO::ImageInput> in;
    if (by_memory) {
        proxy = std::make_unique<OIIO::Filesystem::IOMemReader>(by_memory, size);
        in = OIIO::ImageInput::open(name, nullptr, proxy.get());
    } else {
        in = OIIO::ImageInput::open(name);
    }
    if (!in) return "cannot decode image: " + OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return "image has no pixels";
    if (spec.width > max_side || spec.height > max_side)
        return "image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
               " is outside 1.." + std::to_string(max_side) + " per side";
    out.width = spec.width;
    out.height = spec.height;
    out.channels = std::min(spec.nchannels, max_channels);
    out.alpha_channel = spec.alpha_channel < out.channels ? spec.alpha_channel : -1;
    out.values.assign(size_t(spec.width) * size_t(spec.height) * size_t(out.channels), 0.0f);
    if (!in->read_image(0, 0, 0, out.channels, OIIO::TypeDesc::FLOAT, out.values.data()))
        return "cannot decode image: " + in->geterror();
    in->close();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot decode image: ") + e.what();
}

std::string encode(const std::string& file, const PixelsToWrite& p) try {
    const bool bytes = !p.types.empty() && p.types[0] == ChannelType::u8;
    OIIO::ImageSpec spec(p.width, p.height, int(p.types.size()),
                         bytes ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    bool mixed = false;
    for (ChannelType t : p.types) mixed |= t != p.types[0];
    if (mixed) {
        spec.channelformats.clear();
        for (ChannelType t : p.types) spec.channelformats.push_back(type_desc(t));
    }
    for (size_t c = 0; c < p.names.size() && c < p.types.size(); ++c) spec.channelnames[c] = p.names[c];
    for (const auto& [key, value] : p.attributes) spec.attribute(key, value);
    if (p.srgb) spec.attribute("oiio:ColorSpace", "sRGB");
    if (p.lossless_zip) spec.attribute("compression", "zip");
    auto out = OIIO::ImageOutput::create(file);
    if (!out) return "cannot create image writer: " + OIIO::geterror();
    const OIIO::TypeDesc format = mixed ? OIIO::TypeDesc::UNKNOWN : type_desc(p.types[0]);
    if (!(out->open(file, spec) && out->write_image(format, p.data) && out->close()))
        return "cannot write image: " + out->geterror();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot write image: ") + e.what();
}

std::string read_attributes(const std::string& file, const std::string& prefix,
                            std::vector<std::pair<std::string, std::string>>& out) try {
    auto in = OIIO::ImageInput::open(file);
    if (!in) return "cannot open image: " + OIIO::geterror();
    for (const OIIO::ParamValue& p : in->spec().extra_attribs) {
        const std::string key = p.name().string();
        if (key.rfind(prefix, 0) == 0) out.emplace_back(key, p.get_string());
    }
    return "";
} catch (const std::exception& e) {
    return std::string("cannot open image: ") + e.what();
}

std::string read_u32_channels(const std::string& file, const std::vector<std::string>& names, int& width,
                              int& height, std::vector<std::vector<uint32_t>>& out,
                              std::string& bad_channel) try {
    auto in = OIIO::ImageInput::open(file);
    if (!in) return "cannot open image: " + OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width;
    height = spec.height;
    for (const std::string& channel : names) {
        bad_channel = channel;
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), channel);
        if (it == spec.channelnames.end()) return "channel missing";
        const int c = int(it - spec.channelnames.begin());
        if (spec.channelformat(c) != OIIO::TypeDesc::UINT32) return "expected uint32 data";
        std::vector<uint32_t> values(size_t(spec.width) * size_t(spec.height));
        if (!in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT32, values.data()))
            return "cannot read: " + in->geterror();
        out.push_back(std::move(values));
    }
    bad_channel.clear();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot read image: ") + e.what();
}

// --- plots: the layout comes ready in pixels (io/plot.h); this only draws it.

namespace IBA = OIIO::ImageBufAlgo;

// Drawn at twice the size and filtered down: OIIO's lines are one pixel wide
// and not antialiased.
constexpr int kSupersample = 2;

int canvas_px(double v) { return int(std::lround(v * kSupersample)); }

std::array<float, 3> rgb(PlotColor c) { return {c.r, c.g, c.b}; }

/// The first of `fonts` that OpenImageIO finds and loads; empty if none.
std::string usable_font(const std::vector<std::string>& fonts) {
    for (const std::string& font : fonts)
        if (IBA::text_size("0", 12, font).defined()) return font;
    return {};
}

/// A segment `width` pixels wide: parallel one-pixel lines, offset across the
/// segment's major axis so that steep and flat segments come out equally solid.
void draw_segment(OIIO::ImageBuf& canvas, PlotPoint a, PlotPoint b, PlotColor color, double width) {
    const int x0 = canvas_px(a.x), y0 = canvas_px(a.y), x1 = canvas_px(b.x), y1 = canvas_px(b.y);
    const int lines = std::max(1, int(std::lround(width * kSupersample)));
    const bool flat = std::abs(x1 - x0) >= std::abs(y1 - y0);
    const auto c = rgb(color);
    for (int k = 0; k < lines; ++k) {
        const int o = k - lines / 2;
        if (flat)
            IBA::render_line(canvas, x0, y0 + o, x1, y1 + o, c);
        else
            IBA::render_line(canvas, x0 + o, y0, x1 + o, y1, c);
    }
}

void draw_path(OIIO::ImageBuf& canvas, const PlotPath& p) {
    double phase = 0;  // distance along the dash pattern, carried across vertices
    for (size_t i = 1; i < p.points.size(); ++i) {
        const PlotPoint a = p.points[i - 1], b = p.points[i];
        if (p.dash <= 0) {
            draw_segment(canvas, a, b, p.color, p.width);
            continue;
        }
        const double length = std::hypot(b.x - a.x, b.y - a.y);
        auto at = [&](double s) {
            return PlotPoint{a.x + (b.x - a.x) * s / length, a.y + (b.y - a.y) * s / length};
        };
        for (double s = 0; s < length;) {
            const double in_period = std::fmod(phase + s, 2 * p.dash);
            const double step =
                std::min(length - s, in_period < p.dash ? p.dash - in_period : 2 * p.dash - in_period);
            if (in_period < p.dash) draw_segment(canvas, at(s), at(s + step), p.color, p.width);
            s += step;
        }
        phase += length;
    }
}

void draw_box(OIIO::ImageBuf& canvas, const PlotBox& b) {
    if (b.filled) {
        IBA::render_box(canvas, canvas_px(b.min.x), canvas_px(b.min.y), canvas_px(b.max.x),
                        canvas_px(b.max.y), rgb(b.color), true);
        return;
    }
    const PlotPoint corners[] = {b.min, {b.max.x, b.min.y}, b.max, {b.min.x, b.max.y}, b.min};
    for (int i = 0; i < 4; ++i) draw_segment(canvas, corners[i], corners[i + 1], b.color, 1);
}

IBA::TextAlignX align_x(TextAnchor a) {
    return a == TextAnchor::start ? IBA::TextAlignX::Left
           : a == TextAnchor::end ? IBA::TextAlignX::Right
                                  : IBA::TextAlignX::Center;
}

IBA::TextAlignY align_y(TextBaseline b) {
    return b == TextBaseline::hanging  ? IBA::TextAlignY::Top
           : b == TextBaseline::middle ? IBA::TextAlignY::Center
                                       : IBA::TextAlignY::Baseline;
}

/// Whether text_size found glyphs with pixels: it leaves the bounds at INT_MIN
/// for empty or blank text.
bool has_ink(const OIIO::ROI& box) {
    constexpr int unset = std::numeric_limits<int>::min();
    return box.xbegin != unset && box.ybegin != unset && box.xend > box.xbegin && box.yend > box.ybegin;
}

/// Vertical text: OpenImageIO draws horizontal text only, so the text is drawn
/// into an image of its own, turned a quarter anticlockwise and pasted.
bool draw_vertical_text(OIIO::ImageBuf& canvas, const PlotText& t, const std::string& font,
                        PlotColor background) {
    const int size = canvas_px(t.size), pad = 2;
    const OIIO::ROI box = IBA::text_size(t.text, size, font);
    if (!has_ink(box)) return box.defined();  // blank text: nothing to draw
    OIIO::ImageBuf label(
        OIIO::ImageSpec(box.width() + 2 * pad, box.height() + 2 * pad, 3, OIIO::TypeDesc::FLOAT));
    IBA::fill(label, rgb(background));
    if (!IBA::render_text(label, pad - box.xbegin, pad - box.ybegin, t.text, size, font, rgb(t.color)))
        return false;
    const OIIO::ImageBuf turned = IBA::rotate270(label);
    const int w = turned.spec().width, h = turned.spec().height;
    // Along the text (upwards): the anchor; across it: centred on the point.
    const int bottom = canvas_px(t.at.y) + (t.anchor == TextAnchor::start    ? 0
                                            : t.anchor == TextAnchor::middle ? h / 2
                                                                             : h);
    return IBA::paste(canvas, canvas_px(t.at.x) - w / 2, bottom - h, 0, 0, turned);
}

/// Text with a superscript: both parts are measured, so the pair as a whole
/// is placed as the anchor and baseline ask.
bool draw_text_with_superscript(OIIO::ImageBuf& canvas, const PlotText& t, const std::string& font) {
    const int size = canvas_px(t.size), sup_size = canvas_px(superscript_size(t.size));
    const OIIO::ROI base = IBA::text_size(t.text, size, font);
    const OIIO::ROI sup = IBA::text_size(t.superscript, sup_size, font);
    if (!has_ink(base) || !has_ink(sup)) return false;
    const int gap = kSupersample, width = base.xend + gap + sup.xend;
    const int x = canvas_px(t.at.x) - (t.anchor == TextAnchor::start    ? 0
                                       : t.anchor == TextAnchor::middle ? width / 2
                                                                        : width);
    // text_size's y range is relative to the baseline (negative: above it).
    const int baseline =
        canvas_px(t.at.y) - (t.baseline == TextBaseline::hanging  ? base.ybegin
                             : t.baseline == TextBaseline::middle ? (base.ybegin + base.yend) / 2
                                                                  : 0);
    return IBA::render_text(canvas, x, baseline, t.text, size, font, rgb(t.color)) &&
           IBA::render_text(canvas, x + base.xend + gap, baseline - canvas_px(superscript_rise(t.size)),
                            t.superscript, sup_size, font, rgb(t.color));
}

/// Why texts are missing when no font of `fonts` was found; `what` names the image.
std::string no_font_warning(const std::vector<std::string>& fonts, const std::string& what) {
    return "no TrueType font found (tried " + join(fonts) +
           "; Debian: apt-get install fonts-dejavu-core): " + what + " has no text";
}

bool draw_text(OIIO::ImageBuf& canvas, const PlotText& t, const std::string& font, PlotColor background) {
    if (t.vertical) return draw_vertical_text(canvas, t, font, background);
    if (!t.superscript.empty()) return draw_text_with_superscript(canvas, t, font);
    return IBA::render_text(canvas, canvas_px(t.at.x), canvas_px(t.at.y), t.text, canvas_px(t.size), font,
                            rgb(t.color), align_x(t.anchor), align_y(t.baseline));
}

std::string draw_plot(const std::string& file, const PlotDrawing& d, std::string& warning) try {
    if (d.width <= 0 || d.height <= 0 || d.width > 16384 || d.height > 16384) return "plot size out of range";
    OIIO::ImageBuf canvas(
        OIIO::ImageSpec(d.width * kSupersample, d.height * kSupersample, 3, OIIO::TypeDesc::FLOAT));
    IBA::fill(canvas, rgb(d.background));
    const std::string font = usable_font(d.fonts);
    if (font.empty()) warning = no_font_warning(d.fonts, "the PNG plot");
    bool text_failed = false;
    for (const PlotItem& item : d.items) {
        if (const auto* path = std::get_if<PlotPath>(&item))
            draw_path(canvas, *path);
        else if (const auto* box = std::get_if<PlotBox>(&item))
            draw_box(canvas, *box);
        else if (const auto* text = std::get_if<PlotText>(&item); text && !font.empty())
            text_failed |= !draw_text(canvas, *text, font, d.background);
    }
    if (text_failed && warning.empty()) warning = "some plot texts could not be drawn with the font " + font;
    const OIIO::ImageBuf image = IBA::resize(canvas, "", 0, OIIO::ROI(0, d.width, 0, d.height, 0, 1, 0, 3));
    if (image.has_error()) return "cannot draw the plot: " + image.geterror();
    if (!image.write(file, OIIO::TypeDesc::UINT8)) return "cannot write the plot: " + image.geterror();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot draw the plot: ") + e.what();
}

std::string draw_texts(int width, int height, float* pixels, const std::vector<PlotText>& texts,
                       const std::vector<std::string>& fonts, std::string& warning) try {
    if (width <= 0 || height <= 0) return "image size out of range";
    const std::string font = usable_font(fonts);
    if (font.empty()) {
        warning = no_font_warning(fonts, "the image");
        return "";
    }
    // Drawn straight into the caller's pixels: the buffer is wrapped, not copied.
    OIIO::ImageBuf canvas(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT), pixels);
    for (const PlotText& t : texts)
        if (!IBA::render_text(canvas, int(std::lround(t.at.x)), int(std::lround(t.at.y)), t.text,
                              int(std::lround(t.size)), font, rgb(t.color), align_x(t.anchor),
                              align_y(t.baseline)))
            warning = "some texts could not be drawn with the font " + font;
    return "";
} catch (const std::exception& e) {
    return std::string("cannot draw text: ") + e.what();
}

constexpr ImageCodecApi kApi{kImageCodecVersion, decode,    encode,    read_attributes,
                             read_u32_channels,  draw_plot, draw_texts};

}  // namespace
}  // namespace sahara

extern "C" __attribute__((visibility("default"))) const sahara::ImageCodecApi* sahara_image_codec_api() {
    return &sahara::kApi;
}
