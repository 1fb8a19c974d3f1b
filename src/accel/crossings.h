#pragma once
/// Every triangle a ray crosses, not only the nearest: the all-hits query of the
/// Python ray caster (intersect_all, count_intersections). It walks the wide8 tree
/// with the any-hit traversal, whose leaves here never report a hit, so no child is
/// culled and tmax never shrinks; leaves are tested with the renderer's SIMD block
/// test and the EdgesPerturbed tie-break (geometry/triangle.h), so a ray through a
/// shared edge or vertex crosses there exactly once.
#include <span>
#include <vector>

#include "accel/bvh4_leaf.h"
#include "accel/bvh_wide.h"
#include "geometry/hit.h"

namespace sahara {

/// Appends to `out` every crossing of `ray` with t in (ray.tmin, ray.tmax) with the
/// triangles of `tree` (leaf references index `blocks`, as Accelerator::leaf_blocks()),
/// in traversal order (not sorted). Lanes of other primitive kinds are skipped.
void collect_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                       std::vector<Hit>& out);

/// The number of crossings collect_crossings would append.
uint32_t count_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray);

}  // namespace sahara
