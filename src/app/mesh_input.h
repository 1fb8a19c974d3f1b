#pragma once
/// A small private OBJ reader for the BVH tools (`sahara bvh`, `bench`,
/// `trace`) and their tests, until they switch to io/model_loader.h.
///
/// Primitive order (the `trace` command's primitive indices): triangles in
/// file order; a polygon v0 v1 ... vk is fan-split into (v0,v1,v2),
/// (v0,v2,v3), ..., (v0,vk-1,vk). Concave polygons are fan-split the same way,
/// without ear clipping, so their fan may cover area outside the polygon.
/// Zero-area triangles are KEPT so that indices stay file-order indices.
/// Only positions are read (the tools need no normals, UVs or materials).
#include <filesystem>
#include <string>

#include "scene/scene.h"
#include "scene/scene_desc.h"

namespace sahara {

/// Reads positions and fan-split triangles of an OBJ file; throws InputError
/// for a missing or malformed file, an out-of-range index or a non-finite position.
TriangleMesh read_obj_triangles(const std::filesystem::path& file);

/// Triangles of any mesh file: OBJ through read_obj_triangles (file order kept,
/// degenerate triangles kept), .gltf/.glb through the glTF loader with every
/// mesh of the default scene merged into one.
TriangleMesh read_mesh_triangles(const std::filesystem::path& file);

/// A Scene holding only `mesh`'s triangles (no BVH yet; call build_accelerator or build an Accelerator).
Scene scene_from_mesh(const TriangleMesh& mesh);

/// Whether the BVH tools read `file` as a scene file (extension .json) rather than a mesh.
bool is_scene_file(const std::filesystem::path& file);

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

/// Counts of the scene's bounded primitives by kind, e.g. "120 triangles, 2 spheres"
/// (kinds with none left out, planes never listed; "none" if nothing is left).
std::string primitive_kinds_text(const Scene& scene, bool with_triangles = true);

}  // namespace sahara
