#pragma once
/// Shape statistics of a Bvh (for `sahara bvh`) and a structural validator (for tests).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_wide.h"

namespace sahara {

struct BvhStats {
    size_t primitives = 0;
    size_t nodes = 0;  ///< reachable nodes (the padding node not counted)
    size_t leaves = 0;
    int max_depth = 0;           ///< root = depth 0
    double mean_leaf_depth = 0;  ///< averaged over leaves
    /// leaf_size_histogram[k] = number of leaves holding k primitives.
    std::vector<size_t> leaf_size_histogram;
    /// SAH cost normalised by the root's surface area:
    /// sum over inner nodes of traversal * A/A_root + over leaves of intersection * n * A/A_root.
    double sah_cost = 0;
    size_t bytes = 0;  ///< nodes + slot indices
};

/// Walks the tree once; `params` supplies the cost constants of the SAH cost.
BvhStats compute_bvh_stats(const Bvh& bvh, const BvhBuildParams& params = {});

/// Shape of a wide (4- or 8-wide) tree, with the SAH statistics defined as
/// Embree's verbose build report defines them, so the two trees compare directly:
/// node term = sum over wide nodes of area(node) / area(root); leaf term = sum
/// over leaves of area(leaf) * (leaf blocks) / area(root).
struct WideBvhStats {
    size_t nodes = 0;
    size_t children = 0;  ///< over all nodes (children / nodes: the fill)
    size_t leaves = 0;
    size_t leaf_primitives = 0;
    size_t leaf_blocks = 0;  ///< leaves counted in blocks of `block_size` primitives
    double sah_nodes = 0, sah_leaves = 0;
};

/// `block_size`: primitives tested together in a leaf (4 for the block layouts, else 1).
WideBvhStats compute_wide_bvh_stats(const Bvh8& bvh, uint32_t block_size);

/// Checks the invariants of a built tree against the boxes it was built from:
/// every primitive in exactly one leaf, every node reached once, every child's
/// bounds inside its parent's, every leaf's bounds around its primitives, depth
/// below kBvhMaxDepth, sibling pairs at even indices. Returns an empty string when valid, else the first
/// violation.
std::string validate_bvh(const Bvh& bvh, std::span<const Bounds3> prim_boxes);

}  // namespace sahara
