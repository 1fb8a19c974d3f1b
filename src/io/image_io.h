#pragma once
/// Image file input (declaration the scene parser relies on; the lead's
/// OpenImageIO implementation provides the definition).
#include <filesystem>
#include <memory>

#include "scene/scene_desc.h"

namespace sahara {

/// Reads an image file into linear float RGBA; throws InputError on failure.
std::shared_ptr<const Image> read_image(const std::filesystem::path& file, bool srgb_to_linear);

}  // namespace sahara
