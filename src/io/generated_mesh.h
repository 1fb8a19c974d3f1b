#pragma once
/// Meshes made in memory, with no file: `sahara bench --generated-mesh N` and the
/// tests build and trace meshes of any size with them.
#include <cstddef>
#include <cstdint>

#include "desc/scene_desc.h"

namespace sahara {

/// The tessellation of a displaced sphere: `rings` rings of `segments` vertices
/// between the two poles; each pole is joined to its ring by a fan of `segments`
/// triangles and neighbouring rings by 2 * segments, so there are exactly
/// 2 * rings * segments triangles and rings * segments + 2 vertices.
struct SphereGrid {
    uint32_t rings = 0;
    uint32_t segments = 0;
    size_t triangles() const { return 2 * size_t(rings) * segments; }
};

/// The grid with exactly `triangles` triangles and rings as close as the count
/// allows to half the segments (the most even triangles). Throws UsageError unless
/// `triangles` is even and at least 6, and the vertices fit 32-bit indices.
SphereGrid sphere_grid_for(size_t triangles);

/// A closed, consistently wound (counter-clockwise seen from outside) sphere of
/// radius about 1 around the origin, its radius displaced by a few smooth waves
/// (by under 25%; the surface stays star-shaped, so it never folds over itself). Deterministic: the same
/// grid gives the same mesh, bit for bit.
TriangleMesh make_displaced_sphere(const SphereGrid& grid);

}  // namespace sahara
