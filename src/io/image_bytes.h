#pragma once
/// Decoding of images that live inside model files (glTF data URIs and
/// bufferViews), and the pixel conversions shared by the loaders.
#include <cstddef>
#include <memory>
#include <string>

#include "scene/scene_desc.h"

namespace sahara {

/// Largest accepted width or height of a decoded image.
inline constexpr int kMaxImageSide = 32768;

/// sRGB transfer function inverse (IEC 61966-2-1) for one channel value.
float srgb_to_linear_value(float c);

/// Decodes an encoded PNG/JPEG (any format OpenImageIO reads from memory) to
/// linear RGBA. Errors throw InputError "FILE: ELEMENT: what".
std::shared_ptr<const Image> decode_image_bytes(const unsigned char* data, size_t size, bool srgb_to_linear,
                                                const std::string& file, const std::string& element);

}  // namespace sahara
