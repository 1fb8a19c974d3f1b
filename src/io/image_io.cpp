#include "io/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "base/error.h"
#include "io/files.h"
#include "io/image_bytes.h"
#include "io/image_codec.h"

namespace sahara {

namespace fs = std::filesystem;

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
    DecodedPixels px;
    if (const std::string why = image_codec(name).decode(name, nullptr, 0, kMaxImageSide, 64, px);
        !why.empty())
        throw input_error(name, "", why);
    auto img = std::make_shared<Image>();
    expand_to_rgba(px, srgb_to_linear, *img);
    return img;
}

bool is_supported_output(const fs::path& file) { return is_output_image_kind(file_kind(file)); }

bool is_hdr_output(const fs::path& file) { return file_kind(file) != FileKind::png; }

void check_output_path(const fs::path& file) {
    const std::string name = file.string();
    if (!is_supported_output(file))
        throw input_error(name, "", "unsupported output format (use .png, .exr, .hdr or .pfm)");
    fs::path dir = file.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw input_error(name, "",
                          "output directory '" + dir.string() +
                              (fs::exists(dir, ec) ? "' is not a directory" : "' does not exist"));
    // Checked now, not when the finished image cannot be renamed onto it.
    if (fs::is_directory(file, ec)) throw input_error(name, "", "is a directory, not an image file name");
    if (::access(dir.c_str(), W_OK) != 0) throw input_error(name, "", "output directory is not writable");
    if (file_kind(file) != FileKind::pfm)
        image_codec(name);  // a missing codec fails here, not after the render
}

namespace {

/// Pixel data in the file's layout: RGB as 8-bit sRGB or float, then the extra
/// uint32 channels (all 4-byte channels share one word buffer).
struct EncodedPixels {
    PixelsToWrite spec;
    std::vector<unsigned char> bytes;
    std::vector<uint32_t> words;
};

void encode_pixels(const fs::path& file, int width, int height, const std::vector<float>& rgb,
                   const std::vector<ExtraChannel>& extra, EncodedPixels& e) {
    const bool hdr = is_hdr_output(file);
    const bool with_extra = file_kind(file) == FileKind::exr && !extra.empty();
    e.spec.width = width;
    e.spec.height = height;
    e.spec.types.assign(3, hdr ? ChannelType::f32 : ChannelType::u8);
    e.spec.srgb = !hdr;
    const size_t n = size_t(width) * size_t(height);
    if (!hdr) {
        e.bytes.resize(rgb.size());
        for (size_t i = 0; i < rgb.size(); ++i)
            e.bytes[i] = (unsigned char)std::lround(std::clamp(srgb_encode(rgb[i]), 0.0f, 1.0f) * 255.0f);
        e.spec.data = e.bytes.data();
        return;
    }
    const size_t stride = 3 + (with_extra ? extra.size() : 0);
    e.words.resize(n * stride);
    for (size_t i = 0; i < n; ++i) std::memcpy(&e.words[i * stride], &rgb[i * 3], 3 * sizeof(float));
    e.spec.data = e.words.data();
    if (!with_extra) return;
    e.spec.names = {"R", "G", "B"};
    for (size_t c = 0; c < extra.size(); ++c) {
        e.spec.names.push_back(extra[c].name);
        e.spec.types.push_back(ChannelType::u32);
        for (size_t i = 0; i < n; ++i) e.words[i * stride + 3 + c] = extra[c].values[i];
    }
    e.spec.lossless_zip = true;  // the extra channels must survive bit for bit
}

/// Writes linear RGB as a portable float map: "PF", the size, -1 (little-endian
/// floats), then the rows bottom to top. Written here, not by OpenImageIO: the
/// 2.4 release Debian ships reads PFM but has no writer for it. Returns "" or why it failed.
std::string write_pfm(const fs::path& path, int width, int height, const std::vector<float>& rgb) {
    static_assert(std::endian::native == std::endian::little, "the header below declares little-endian data");
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return std::string("cannot create the file: ") + std::strerror(errno);
    bool ok = std::fprintf(f, "PF\n%d %d\n-1.0\n", width, height) > 0;
    const size_t row = 3 * size_t(width);
    for (int y = height - 1; ok && y >= 0; --y)
        ok = std::fwrite(&rgb[size_t(y) * row], sizeof(float), row, f) == row;
    ok = std::fclose(f) == 0 && ok;
    return ok ? std::string() : std::string("cannot write the file: ") + std::strerror(errno);
}

}  // namespace

void write_image(const fs::path& file, int width, int height, const std::vector<float>& rgb,
                 const ImageMetadata& metadata, const std::vector<ExtraChannel>& extra) {
    const std::string name = file.string();
    const bool pfm = file_kind(file) == FileKind::pfm;
    const ImageCodecApi* codec = pfm ? nullptr : &image_codec(name);
    EncodedPixels pixels;
    if (!pfm) encode_pixels(file, width, height, rgb, extra, pixels);
    for (const auto& [key, value] : metadata) pixels.spec.attributes.emplace_back("sahara:" + key, value);
    pixels.spec.attributes.emplace_back("Software", std::string("sahara ") + SAHARA_VERSION);

    write_via_temporary(
        file,
        [&](const fs::path& tmp) {
            return pfm ? write_pfm(tmp, width, height, rgb) : codec->encode(tmp.string(), pixels.spec);
        },
        "image");
}

ImageMetadata read_image_metadata(const fs::path& file) {
    const std::string name = file.string();
    ImageMetadata meta;
    if (const std::string why = image_codec(name).read_attributes(name, "sahara:", meta); !why.empty())
        throw input_error(name, "", why);
    for (auto& kv : meta) kv.first.erase(0, 7);  // drop "sahara:"
    return meta;
}

std::vector<ExtraChannel> read_extra_channels(const fs::path& file, const std::vector<std::string>& names,
                                              int* width, int* height) {
    const std::string name = file.string();
    std::vector<std::vector<uint32_t>> values;
    std::string bad_channel;
    if (const std::string why =
            image_codec(name).read_u32_channels(name, names, *width, *height, values, bad_channel);
        !why.empty())
        throw input_error(name, bad_channel, why);
    std::vector<ExtraChannel> out;
    for (size_t c = 0; c < names.size(); ++c) out.push_back(ExtraChannel{names[c], std::move(values[c])});
    return out;
}

void write_image_u8(const fs::path& file, int width, int height, int channels, const unsigned char* data) {
    const std::string name = file.string();
    PixelsToWrite p;
    p.width = width;
    p.height = height;
    p.types.assign(size_t(channels), ChannelType::u8);
    p.data = data;
    if (const std::string why = image_codec(name).encode(name, p); !why.empty())
        throw input_error(name, "", why);
}

}  // namespace sahara
