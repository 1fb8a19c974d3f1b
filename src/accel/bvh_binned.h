#pragma once
/// The binned SAH builder (Wald 2007), internal to accel: bvh_build.cpp calls it
/// for BvhBuilder::binned and as the first step of BvhBuilder::reinsert.
#include "accel/bvh.h"

namespace sahara {

/// Builds `out` (nodes and prim_indices) over `input`. Parallel near the root
/// (binning and partitioning in fixed chunks) and over subtrees (OpenMP tasks);
/// the result is the same for every thread count. `params` are already clamped.
void build_binned_bvh(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out);

}  // namespace sahara
