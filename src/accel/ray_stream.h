#pragma once
/// Ray-stream traversal of the upper levels of a BVH8 (after Barringer and
/// Akenine-Möller, "Dynamic ray stream traversal", 2014, and Wald/Benthin's hybrid
/// traversal): a few hundred rays that a sort has made neighbours go down the tree
/// together. At each node the rays that reached it are tested eight at a time against
/// one child box, and the ids of those that hit go to that child's list. Where a list
/// is short, the child is a leaf or the stream is deep, the child (with the ray's entry
/// distance) goes to each of its rays' frontier instead; each ray then finishes alone
/// from its frontier with the single-ray traversal (Accelerator::intersect_frontier),
/// which visits those subtrees nearest first and culls them with its tmax.
///
/// The box test is the single-ray AVX test (bvh8_distances_avx) with the roles of rays
/// and children swapped, the same operations on the same operands, so a ray reaches the
/// same subtrees as it would alone before its first hit. The stream has no tmax culling:
/// no ray has tested a leaf yet when its entries are made.
#include <cstdint>

#include "accel/bvh_traverse.h"
#include "accel/bvh_wide.h"

namespace sahara {

/// Subtrees one ray can keep from the stream; a ray with more takes the single-ray
/// traversal from the root (RayStream::overflow).
inline constexpr int kStreamFrontierCap = 32;
/// Rays of one stream.
inline constexpr int kMaxStreamRays = 256;
/// A child with fewer rays than this goes to its rays' frontiers: below it, testing
/// eight rays at a time against one box no longer saves the single-ray step's work.
inline constexpr int kMinStreamListRays = 16;
/// Levels below the root the stream walks at most. Deeper, its rays meet subtrees that
/// their own traversal would have culled after a first hit.
inline constexpr int kMaxStreamDepth = 2;

/// Counts of one or more streams, for the stream's tuning (bench/ and docs only).
struct RayStreamStats {
    uint64_t rays = 0;
    uint64_t node_visits[kMaxStreamDepth + 1] = {};     ///< stream nodes tested, by depth
    uint64_t ray_node_tests[kMaxStreamDepth + 1] = {};  ///< rays tested at those nodes
    uint64_t frontier_entries = 0;
    uint64_t overflows = 0;
};

/// The rays of one stream and their frontiers: structure-of-arrays box constants (those
/// of Bvh8RayAvx per ray), filled by add(); trace_stream_frontiers fills the rest.
/// About 80 kB: one per thread, reused.
struct alignas(64) RayStream {
    int size = 0;
    float org[3][kMaxStreamRays];
    float ninv[3][kMaxStreamRays];         ///< -1 / d
    float inv_far[3][kMaxStreamRays];      ///< 1 / d * kRobustFarScale
    int32_t tmin_bits[kMaxStreamRays];     ///< max(tmin, 0) as an integer (bvh8_distances_avx)
    int32_t neg_tmax_far[kMaxStreamRays];  ///< -tmax * kRobustFarScale as an integer
    int32_t neg_axes[kMaxStreamRays];      ///< bit a: direction a is negative (its near plane is hi)
    int32_t frontier_count[kMaxStreamRays];
    bool overflow[kMaxStreamRays];
    /// Per ray: stack entries (reference low, entry distance high), sorted farthest first.
    uint64_t frontier[kMaxStreamRays][kStreamFrontierCap];

    void clear() { size = 0; }
    /// Appends a ray (size < kMaxStreamRays).
    void add(const BvhRay& r);
};

/// Walks the stream's rays down `bvh` (not empty, root not a leaf) and leaves each ray's
/// frontier in `s`, sorted farthest first. AVX-512 or AVX2 by active_simd_path (the
/// caller checks that one of them runs). `stats` may be null.
void trace_stream_frontiers(const Bvh8& bvh, RayStream& s, RayStreamStats* stats);

}  // namespace sahara
