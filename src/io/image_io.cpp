#include "io/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>
#include <system_error>

#include "base/error.h"

namespace sahara {

namespace fs = std::filesystem;
namespace OIIO = OIIO_NAMESPACE;

namespace {

constexpr int kMaxImageSide = 32768;

std::string lower_extension(const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
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
        throw input_error(name, "", "image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
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
    if (!fs::is_directory(dir, ec)) throw input_error(name, "", "output directory '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw input_error(name, "", "output directory is not writable");
}

void write_image(const fs::path& file, int width, int height, const std::vector<float>& rgb,
                 const ImageMetadata& metadata) {
    const std::string name = file.string();
    const bool hdr = is_hdr_output(file);
    // The temporary keeps the real extension so OIIO picks the right writer.
    fs::path tmp = file;
    std::string tmp_name(".");  // built piecewise: gcc 12 warns falsely (-Wrestrict) on a + chain here
    tmp_name.append(file.stem().string()).append(".tmp").append(std::to_string(::getpid()));
    tmp_name.append(file.extension().string());
    tmp.replace_filename(tmp_name);

    OIIO::ImageSpec spec(width, height, 3, hdr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    for (const auto& [key, value] : metadata) spec.attribute("sahara:" + key, value);
    spec.attribute("Software", std::string("sahara ") + SAHARA_VERSION);
    if (!hdr) spec.attribute("oiio:ColorSpace", "sRGB");

    std::vector<unsigned char> bytes;
    const void* data = rgb.data();
    if (!hdr) {
        bytes.resize(rgb.size());
        for (size_t i = 0; i < rgb.size(); ++i)
            bytes[i] = (unsigned char)std::lround(std::clamp(srgb_encode(rgb[i]), 0.0f, 1.0f) * 255.0f);
        data = bytes.data();
    }
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw input_error(name, "", "cannot create image writer: " + OIIO::geterror());
    bool ok = out->open(tmp.string(), spec) &&
              out->write_image(hdr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8, data) && out->close();
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

}  // namespace sahara
