#include "io/image_bytes.h"

#include <cmath>
#include <cstring>

#include "base/error.h"
#include "io/image_codec.h"
#include "io/image_io.h"

namespace sahara {

namespace {

/// OpenImageIO picks its reader by file extension; embedded images carry no
/// name, so the extension comes from the format's magic number.
std::string format_hint(const unsigned char* data, size_t size) {
    if (size >= 8 && std::memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0) return "embedded.png";
    if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) return "embedded.jpg";
    if (size >= 6 && (std::memcmp(data, "GIF87a", 6) == 0 || std::memcmp(data, "GIF89a", 6) == 0))
        return "embedded.gif";
    if (size >= 2 && data[0] == 'B' && data[1] == 'M') return "embedded.bmp";
    return "";
}

uint32_t be32(const unsigned char* p) {
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

/// CRC-32 (ISO 3309, as the PNG specification defines it) of `n` bytes.
uint32_t crc32(const unsigned char* p, size_t n) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

/// Walks a PNG's chunk list (bounds, CRCs, IHDR first, IEND last). libpng
/// reports such damage by longjmp through OpenImageIO, which leaks its error
/// text; catching it here first also gives a clearer message.
std::string png_structure_error(const unsigned char* data, size_t size) {
    size_t at = 8;
    for (int index = 0;; ++index) {
        if (size - at < 12) return "PNG is truncated (chunk " + std::to_string(index) + " header)";
        const size_t length = be32(data + at);
        const std::string type(reinterpret_cast<const char*>(data + at + 4), 4);
        if (length > size - at - 12) return "PNG chunk " + std::to_string(index) + " is truncated";
        if (crc32(data + at + 4, length + 4) != be32(data + at + 8 + length))
            return "PNG chunk " + std::to_string(index) + " has a bad CRC";
        if (index == 0 && type != "IHDR") return "PNG does not start with IHDR";
        at += 12 + length;
        if (type == "IEND") return "";
    }
}

}  // namespace

void expand_to_rgba(const DecodedPixels& px, bool srgb_to_linear, Image& out) {
    out.width = px.width;
    out.height = px.height;
    const size_t n = size_t(px.width) * size_t(px.height);
    const int channels = px.channels, alpha = px.alpha_channel;
    out.rgba.resize(n * 4);
    for (size_t i = 0; i < n; ++i) {
        const float* src = &px.values[i * size_t(channels)];
        float* dst = &out.rgba[i * 4];
        for (int c = 0; c < 3; ++c) {
            // Grey (and grey+alpha) images replicate their one colour channel.
            float v = src[channels >= 3 ? c : 0];
            if (!std::isfinite(v)) v = 0.0f;
            dst[c] = srgb_to_linear ? srgb_decode(v) : v;
        }
        dst[3] = alpha >= 0 ? src[alpha] : (channels == 2 ? src[1] : (channels >= 4 ? src[3] : 1.0f));
    }
}

std::shared_ptr<const Image> decode_image_bytes(const unsigned char* data, size_t size, bool srgb_to_linear,
                                                const std::string& file, const std::string& element) {
    const std::string hint = format_hint(data, size);
    if (hint.empty()) throw input_error(file, element, "image data is not PNG, JPEG, GIF or BMP");
    if (hint == "embedded.png")
        if (const std::string why = png_structure_error(data, size); !why.empty())
            throw input_error(file, element, "cannot decode image: " + why);
    DecodedPixels px;
    if (const std::string why = image_codec(file).decode(hint, data, size, kMaxImageSide, 4, px);
        !why.empty())
        throw input_error(file, element, why);
    auto image = std::make_shared<Image>();
    expand_to_rgba(px, srgb_to_linear, *image);
    return image;
}

}  // namespace sahara
