#pragma once
/// Image file input (OpenImageIO) into sahara's linear RGBA float Image.
#include <filesystem>
#include <memory>

#include "scene/scene_desc.h"

namespace sahara {

/// Reads an image file as linear RGBA float, row 0 at the top. With
/// `srgb_to_linear` the RGB channels are decoded from sRGB (colour textures);
/// alpha is never converted. Throws InputError naming the file.
std::shared_ptr<const Image> read_image(const std::filesystem::path& file, bool srgb_to_linear);

}  // namespace sahara
