#pragma once
/// Geometry helpers shared by the model loaders: polygon triangulation,
/// degenerate-triangle removal, transforms and bounds of TriangleMesh.
#include <cstdint>
#include <span>
#include <vector>

#include "math/bounds.h"
#include "math/transform.h"
#include "desc/scene_desc.h"

namespace sahara {

/// Polygon normal by Newell's method (M. Newell, as given in Sutherland et al.,
/// "A Characterization of Ten Hidden-Surface Algorithms", 1974): robust for
/// non-planar and concave polygons. Its length is twice the polygon's area.
Vec3d newell_normal(std::span<const Vec3> polygon);

/// Triangulates a simple polygon (convex or concave, possibly slightly
/// non-planar) by ear clipping in the plane of its Newell normal. Appends
/// polygon.size() - 2 triangles as local vertex indices (3 each) to `out`,
/// wound like the polygon. Self-intersecting input still yields n - 2 triangles.
void triangulate_polygon(std::span<const Vec3> polygon, std::vector<uint32_t>& out);

/// Unit normal of triangle (a, b, c) wound counter-clockwise, or zero if it has no area.
Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c);

/// True if the triangle has zero area in float arithmetic (repeated or collinear corners).
bool is_degenerate(const Vec3& a, const Vec3& b, const Vec3& c);

/// Removes zero-area triangles (and their material_ids); returns how many went.
size_t remove_degenerate(TriangleMesh& mesh);

/// Applies `world_from_model` to positions and normals; a mirroring transform
/// (negative determinant) swaps each triangle's winding so fronts stay fronts.
void transform_mesh(TriangleMesh& mesh, const Mat4& world_from_model);

/// Bounding box of the positions the mesh's triangles use.
Bounds3 mesh_bounds(const TriangleMesh& mesh);

}  // namespace sahara
