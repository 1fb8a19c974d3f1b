#pragma once
/// The spatial-split builder (BvhBuilder::sbvh, bvh_sbvh.cpp), called by build_bvh.
#include "accel/bvh.h"

namespace sahara {

/// Builds `out` (empty on entry) with object and spatial splits; see bvh_sbvh.cpp.
void build_sbvh(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out);

/// Bounds of the part of triangle v[0..2] with lo <= p[axis] <= hi, rounded outward
/// on the other axes (empty when the triangle misses the slab).
Bounds3 clip_triangle_to_slab(const Vec3 v[3], int axis, float lo, float hi);

}  // namespace sahara
