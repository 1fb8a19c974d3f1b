#pragma once
/// What the commands read: the scene of `render` and `converge`, and what the
/// BVH tools (`sahara bvh`, `bench`, `trace`) read: a mesh
/// (io/mesh_triangles.h, scene/mesh_scene.h) or a whole scene file. The file
/// kind comes from io/files.h, so the extension's case does not matter.
#include <filesystem>
#include <optional>
#include <string>

#include "io/mesh_triangles.h"
#include "scene/mesh_scene.h"
#include "scene/scene.h"

namespace sahara {

/// The scene of `render` and `converge`: the file parsed as a scene (any
/// extension but a model's), or the built-in scene when none is given. A model
/// file (.obj, .gltf, .glb) is an InputError that points to `sahara view`.
SceneDesc read_scene_argument(const std::optional<std::string>& file);

/// What `sahara bvh` and `bench` trace: a mesh or a whole scene file.
struct ToolInput {
    Scene scene;  ///< all primitives (a mesh: triangles only, through scene_from_mesh)
    /// The scene's triangles alone (positions and indices; triangle i = scene
    /// triangle i): what Embree gets and what the double-precision arbitration tests.
    TriangleMesh triangles;
    bool from_scene_file = false;  ///< true: scene.camera is the file's camera
};

/// Reads a mesh (read_mesh_triangles) or, for a .json file, parses and builds
/// the scene (scene_parser.h, build_scene); throws InputError naming the file.
ToolInput read_tool_input(const std::filesystem::path& file);

/// A displaced sphere of exactly `triangles` triangles made in memory
/// (io/generated_mesh.h), as a mesh input; throws std::invalid_argument for a count
/// sphere_grid_for refuses.
ToolInput generated_tool_input(size_t triangles);

/// Counts of the scene's bounded primitives by kind, e.g. "120 triangles, 2 spheres"
/// (kinds with none left out, planes never listed; "none" if nothing is left).
std::string primitive_kinds_text(const Scene& scene, bool with_triangles = true);

}  // namespace sahara
