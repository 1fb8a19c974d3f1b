#pragma once
/// Triangles of a mesh file for the BVH tools (`sahara bvh`, `bench`, `trace`)
/// and the tests: positions and indices only, no materials.
///
/// Primitive order (the `trace` command's primitive indices): triangles in
/// file order; a polygon v0 v1 ... vk is fan-split into (v0,v1,v2),
/// (v0,v2,v3), ..., (v0,vk-1,vk). Concave polygons are fan-split the same way,
/// without ear clipping, so their fan may cover area outside the polygon.
/// Zero-area triangles are KEPT so that indices stay file-order indices.
/// The OBJ is read by io's loader (load_obj with ObjReadOptions), without its
/// materials; only positions and indices are kept.
#include <filesystem>

#include "desc/scene_desc.h"

namespace sahara {

/// Reads positions and fan-split triangles of an OBJ file; throws InputError
/// for a missing or malformed file, an out-of-range index or a non-finite position.
TriangleMesh read_obj_triangles(const std::filesystem::path& file);

/// Triangles of any mesh file: OBJ through read_obj_triangles (file order kept,
/// degenerate triangles kept), .gltf/.glb (any case) through the glTF loader with every
/// mesh of the default scene merged into one.
TriangleMesh read_mesh_triangles(const std::filesystem::path& file);

}  // namespace sahara
