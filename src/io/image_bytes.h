#pragma once
/// Decoding of images that live inside model files (glTF data URIs and
/// bufferViews), and the pixel conversions shared by the loaders.
#include <cstddef>
#include <memory>
#include <string>

#include "desc/scene_desc.h"

namespace sahara {

/// Largest accepted width or height of a decoded image.
inline constexpr int kMaxImageSide = 32768;

struct DecodedPixels;

/// Expands decoded 1-4 channel pixels (grey, grey+alpha, RGB, RGBA, or more with
/// a declared alpha channel) to RGBA: grey replicates its one colour channel, a
/// missing alpha is 1, non-finite colour values become 0, and with
/// srgb_to_linear the colour channels are sRGB-decoded (srgb_decode).
void expand_to_rgba(const DecodedPixels& px, bool srgb_to_linear, Image& out);

/// Decodes an encoded PNG/JPEG (any format OpenImageIO reads from memory) to
/// linear RGBA. Errors throw InputError "FILE: ELEMENT: what".
std::shared_ptr<const Image> decode_image_bytes(const unsigned char* data, size_t size, bool srgb_to_linear,
                                                const std::string& file, const std::string& element);

}  // namespace sahara
