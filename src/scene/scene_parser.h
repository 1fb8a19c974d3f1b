#pragma once
/// Scene files (JSON, format "scene/1") to plain scene data.
#include <filesystem>
#include <string>

#include "scene/scene_desc.h"

namespace sahara {

/// Reads, parses and validates a scene file; throws InputError naming the file,
/// the JSON path and what was expected.
SceneDesc parse_scene_file(const std::filesystem::path& file);
/// Same for JSON text; `file` is used for messages and relative paths.
SceneDesc parse_scene_json(const std::string& text, const std::filesystem::path& file);
/// The built-in default scene: the workshop's final scene.
SceneDesc default_scene();

}  // namespace sahara
