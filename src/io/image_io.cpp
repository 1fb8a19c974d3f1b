#include "io/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <system_error>

#include "base/error.h"
#include "base/pending_file.h"

namespace sahara {

namespace fs = std::filesystem;
namespace OIIO = OIIO_NAMESPACE;

namespace {

constexpr int kMaxImageSide = 32768;

std::string lower_extension(const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace

float srgb_encode(float v) {
    if (!(v > 0.0f)) return 0.0f;
    if (v <= 0.0031308f) return 12.92f * v;
    return 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float v) {
    if (!(v > 0.0f)) return 0.0f;
    if (v <= 0.04045f) return v / 12.92f;
    return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

std::shared_ptr<const Image> read_image(const fs::path& file, bool srgb_to_linear) {
    const std::string name = file.string();
    if (!fs::exists(file)) throw input_error(name, "", "image file not found");
    auto in = OIIO::ImageInput::open(name);
    if (!in) throw input_error(name, "", "cannot decode image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.width > kMaxImageSide || spec.height > kMaxImageSide)
        throw input_error(name, "",
                          "image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                              " is outside 1..32768 per side");
    const int channels = spec.nchannels;
    std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
        throw input_error(name, "", "cannot decode image: " + in->geterror());
    in->close();

    auto img = std::make_shared<Image>();
    img->width = spec.width;
    img->height = spec.height;
    img->rgba.resize(size_t(spec.width) * size_t(spec.height) * 4);
    const int alpha = spec.alpha_channel;
    for (size_t i = 0, n = size_t(spec.width) * size_t(spec.height); i < n; ++i) {
        const float* src = &pixels[i * size_t(channels)];
        float* dst = &img->rgba[i * 4];
        for (int c = 0; c < 3; ++c) {
            // Grey (and grey+alpha) images replicate their one colour channel.
            float v = src[channels >= 3 ? c : 0];
            if (!std::isfinite(v)) v = 0.0f;
            dst[c] = srgb_to_linear ? srgb_decode(v) : v;
        }
        dst[3] = alpha >= 0 ? src[alpha] : (channels == 2 ? src[1] : (channels >= 4 ? src[3] : 1.0f));
    }
    return img;
}

bool is_supported_output(const fs::path& file) {
    const std::string ext = lower_extension(file);
    return ext == ".png" || ext == ".exr" || ext == ".hdr" || ext == ".pfm";
}

bool is_hdr_output(const fs::path& file) { return lower_extension(file) != ".png"; }

void check_output_path(const fs::path& file) {
    const std::string name = file.string();
    if (!is_supported_output(file))
        throw input_error(name, "", "unsupported output format (use .png, .exr, .hdr or .pfm)");
    fs::path dir = file.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw input_error(name, "", "output directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw input_error(name, "", "output directory is not writable");
}

namespace {

/// Pixel data in the file's layout: RGB as 8-bit sRGB or float, then the extra
/// uint32 channels (all 4-byte channels share one word buffer).
struct EncodedPixels {
    OIIO::ImageSpec spec;
    std::vector<unsigned char> bytes;
    std::vector<uint32_t> words;
    const void* data() const { return bytes.empty() ? static_cast<const void*>(words.data()) : bytes.data(); }
};

EncodedPixels encode_pixels(const fs::path& file, int width, int height, const std::vector<float>& rgb,
                            const std::vector<ExtraChannel>& extra) {
    const bool hdr = is_hdr_output(file);
    const bool with_extra = lower_extension(file) == ".exr" && !extra.empty();
    EncodedPixels e;
    e.spec = OIIO::ImageSpec(width, height, 3, hdr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    const size_t n = size_t(width) * size_t(height);
    if (!hdr) {
        e.bytes.resize(rgb.size());
        for (size_t i = 0; i < rgb.size(); ++i)
            e.bytes[i] = (unsigned char)std::lround(std::clamp(srgb_encode(rgb[i]), 0.0f, 1.0f) * 255.0f);
        return e;
    }
    const size_t stride = 3 + (with_extra ? extra.size() : 0);
    e.words.resize(n * stride);
    for (size_t i = 0; i < n; ++i) std::memcpy(&e.words[i * stride], &rgb[i * 3], 3 * sizeof(float));
    if (!with_extra) return e;
    e.spec.channelformats.assign(3, OIIO::TypeDesc::FLOAT);
    for (size_t c = 0; c < extra.size(); ++c) {
        e.spec.channelnames.push_back(extra[c].name);
        e.spec.channelformats.push_back(OIIO::TypeDesc::UINT32);
        for (size_t i = 0; i < n; ++i) e.words[i * stride + 3 + c] = extra[c].values[i];
    }
    e.spec.nchannels = int(stride);
    e.spec.attribute("compression", "zip");  // lossless: the extra channels must survive bit for bit
    return e;
}

fs::path temp_path_for(const fs::path& file) {
    // The temporary keeps the real extension so OIIO picks the right writer.
    fs::path tmp = file;
    std::string tmp_name(".");  // built piecewise: gcc 12 warns falsely (-Wrestrict) on a + chain here
    tmp_name.append(file.stem().string()).append(".tmp").append(std::to_string(::getpid()));
    tmp_name.append(file.extension().string());
    tmp.replace_filename(tmp_name);
    return tmp;
}

}  // namespace

void write_image(const fs::path& file, int width, int height, const std::vector<float>& rgb,
                 const ImageMetadata& metadata, const std::vector<ExtraChannel>& extra) {
    const std::string name = file.string();
    const fs::path tmp = temp_path_for(file);
    EncodedPixels pixels = encode_pixels(file, width, height, rgb, extra);
    OIIO::ImageSpec& spec = pixels.spec;
    for (const auto& [key, value] : metadata) spec.attribute("sahara:" + key, value);
    spec.attribute("Software", std::string("sahara ") + SAHARA_VERSION);
    if (!is_hdr_output(file)) spec.attribute("oiio:ColorSpace", "sRGB");

    const PendingFile pending(tmp.string());  // a signal during the write removes the temporary
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw input_error(name, "", "cannot create image writer: " + OIIO::geterror());
    bool ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::UNKNOWN, pixels.data()) &&
              out->close();
    if (!ok) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw input_error(name, "", "cannot write image: " + out->geterror());
    }
    std::error_code ec;
    fs::rename(tmp, file, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw input_error(name, "", "cannot move the finished image into place: " + ec.message());
    }
}

ImageMetadata read_image_metadata(const fs::path& file) {
    auto in = OIIO::ImageInput::open(file.string());
    if (!in) throw input_error(file.string(), "", "cannot open image: " + OIIO::geterror());
    ImageMetadata meta;
    for (const OIIO::ParamValue& p : in->spec().extra_attribs) {
        const std::string key = p.name().string();
        if (key.rfind("sahara:", 0) == 0) meta.emplace_back(key.substr(7), p.get_string());
    }
    return meta;
}

std::vector<ExtraChannel> read_extra_channels(const fs::path& file, const std::vector<std::string>& names,
                                              int* width, int* height) {
    const std::string name = file.string();
    auto in = OIIO::ImageInput::open(name);
    if (!in) throw input_error(name, "", "cannot open image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    *width = spec.width;
    *height = spec.height;
    std::vector<ExtraChannel> out;
    for (const std::string& channel : names) {
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), channel);
        if (it == spec.channelnames.end()) throw input_error(name, channel, "channel missing");
        const int c = int(it - spec.channelnames.begin());
        if (spec.channelformat(c) != OIIO::TypeDesc::UINT32)
            throw input_error(name, channel, "expected uint32 data");
        ExtraChannel ch{channel, std::vector<uint32_t>(size_t(spec.width) * size_t(spec.height))};
        if (!in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT32, ch.values.data()))
            throw input_error(name, channel, "cannot read: " + in->geterror());
        out.push_back(std::move(ch));
    }
    return out;
}

}  // namespace sahara
