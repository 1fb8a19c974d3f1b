#pragma once
/// Per-vertex tangents for normal mapping, generated from a mesh's UVs where
/// the file gave none.
#include <array>
#include <vector>

#include "desc/scene_desc.h"

namespace sahara {

/// One tangent per vertex in glTF's form: xyz along increasing u, orthogonal to
/// the vertex normal (the face normals' sum where the mesh has none), w = +1 or
/// -1 so that cross(n, t) * w points along increasing v (-1 where the UVs are
/// mirrored). Empty when the mesh has no UVs; degenerate UV triangles
/// contribute nothing, and a vertex left without a direction gets an arbitrary
/// tangent orthogonal to its normal.
std::vector<std::array<float, 4>> generate_tangents(const TriangleMesh& mesh);

}  // namespace sahara
