#pragma once
/// Reads scene files (format "scene/1", see scenes/FORMAT.md) into plain
/// SceneDesc data, strictly: unknown keys, wrong types and out-of-range values
/// throw InputError naming the file, the JSON path and what was expected.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "io/json_reader.h"
#include "io/model_loader.h"
#include "desc/scene_desc.h"

namespace sahara {

/// The file readers the parser calls; tests substitute their own.
struct SceneLoaders {
    /// Loads a mesh file with `world_from_model` applied, in the glTF material
    /// variant given, if any (default: load_model).
    std::function<LoadedModel(const std::filesystem::path&, const Mat4&, const std::optional<std::string>&)>
        load_model;
    /// Reads an image, optionally sRGB-decoded (default: read_image).
    std::function<std::shared_ptr<const Image>(const std::filesystem::path&, bool srgb_to_linear)> read_image;

    /// The real loaders (io/model_loader.h, io/image_io.h).
    static SceneLoaders standard();
};

/// Reads, parses and validates a scene file; paths inside resolve relative to it.
SceneDesc parse_scene_file(const std::filesystem::path& file);

/// Parses scene JSON text. `file` names the scene in messages and is the base
/// for relative paths (its parent directory).
SceneDesc parse_scene_json(const std::string& text, const std::filesystem::path& file);
/// As above, with substitute loaders.
SceneDesc parse_scene_json(const std::string& text, const std::filesystem::path& file,
                           const SceneLoaders& loaders);

/// Parses an already-parsed JSON document (e.g. built from a Python dict) with
/// the same checks and messages as a file; `file` names it in messages and its
/// parent directory is the base for relative paths.
SceneDesc parse_scene_value(const Json& root, const std::filesystem::path& file);
SceneDesc parse_scene_value(const Json& root, const std::filesystem::path& file, const SceneLoaders& loaders);

/// The built-in scene (the workshop's final image): a red sphere on a big green
/// ground sphere under the white-to-blue gradient sky, z up.
SceneDesc default_scene();

/// Appends a loaded model to `scene`: its materials and textures are appended
/// with every index shifted, its lights appended. With `material_override`,
/// every triangle uses that material instead and the model's own are dropped.
void merge_loaded_model(SceneDesc& scene, LoadedModel&& model, std::optional<uint32_t> material_override);

/// The local origin of a scene whose camera stands at `camera_position`
/// (world coordinates): zero while the camera is within kLocalOriginRadius of
/// the world origin on every axis (scenes there keep their exact floats), else
/// the camera position rounded to the nearest multiple of kLocalOriginGrid on
/// each axis (a camera moving within a cell keeps the origin, so the geometry's
/// floats do not change from frame to frame).
Vec3d choose_local_origin(const Vec3d& camera_position);
inline constexpr double kLocalOriginRadius = 1024;
inline constexpr double kLocalOriginGrid = 64;

/// Inverse of an affine matrix (last row 0 0 0 1, invertible upper 3x3).
Mat4 affine_inverse(const Mat4& m);

}  // namespace sahara
