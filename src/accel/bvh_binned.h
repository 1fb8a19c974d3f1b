#pragma once
/// The binned SAH builder (Wald 2007), internal to accel: bvh_build.cpp calls it
/// for BvhBuilder::binned and as the first step of BvhBuilder::reinsert.
#include "accel/bvh.h"

namespace sahara {

/// Bins per axis the binned builder uses for a range of `primitives` when asked for
/// `bin_count`: at most 8 for ranges of up to 64 primitives, where the bins' fixed cost
/// (clearing, the split search) outweighs the binning, and finer boundaries barely lower
/// the SAH cost there.
inline uint32_t binned_bin_count(uint32_t primitives, uint32_t bin_count) {
    return primitives <= 64 && bin_count > 8 ? 8 : bin_count;
}

/// Builds `out` (nodes and prim_indices) over `input`. Parallel near the root
/// (binning and partitioning in fixed chunks) and over subtrees (OpenMP tasks);
/// the result is the same for every thread count. `params` are already clamped.
void build_binned_bvh(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out);

}  // namespace sahara
