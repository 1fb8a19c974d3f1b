#pragma once
/// A Scene made of one triangle mesh, for the BVH tools and the tests.
#include "desc/scene_desc.h"
#include "scene/scene.h"

namespace sahara {

/// A Scene holding only `mesh`'s triangles (no BVH yet; call build_accelerator or build an Accelerator).
Scene scene_from_mesh(const TriangleMesh& mesh);

}  // namespace sahara
