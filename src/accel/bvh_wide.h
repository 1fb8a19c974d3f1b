#pragma once
/// Wide BVHs (the BVH8 of the wide8 layout) collapsed from the binary SAH tree: each
/// node holds the boxes of up to N children in structure-of-arrays form, so one ray
/// tests all children in one SIMD step (wide_box_test.h; traverse_wide.h walks the
/// tree). Which binary nodes are merged into one wide node is chosen to minimise the
/// summed area of the wide nodes (bvh_wide.cpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"  // kNoNode

namespace sahara {

/// A child reference (BvhWideNode::child, and the traversal's stack entries): an inner
/// node's byte offset in BvhWide::nodes (a multiple of the node size, so its low
/// kLeafCountBits are 0), or a leaf, first << kLeafCountBits | count with count in
/// [1, kMaxWideLeafCount] (first: its first slot, or its first TriangleBlock4 in the block
/// layouts). The traversal's stack entries are then 8 bytes, one reference and one
/// distance, and one test of the low bits tells a leaf.
constexpr uint32_t kLeafCountBits = 6;
constexpr uint32_t kMaxWideLeafCount = (1u << kLeafCountBits) - 1;
/// Slots (and blocks) a leaf reference can start at: [0, kMaxWideLeafFirst].
constexpr uint32_t kMaxWideLeafFirst = 0xFFFFFFFFu >> kLeafCountBits;
inline uint32_t wide_leaf_ref(uint32_t first, uint32_t count) { return first << kLeafCountBits | count; }
/// A reference's leaf count; 0: an inner node.
inline uint32_t ref_count(uint32_t ref) { return ref & kMaxWideLeafCount; }
/// A leaf reference's first slot (or block).
inline uint32_t ref_first(uint32_t ref) { return ref >> kLeafCountBits; }

/// One N-wide node; child c is empty (child[c] == kNoNode), inner (child = the node's
/// byte offset) or a leaf (child = wide_leaf_ref(first, count)). The alignment pads it
/// to whole cache lines (the last one half used).
template <int N>
struct alignas(64) BvhWideNode {
    float lo_x[N], hi_x[N], lo_y[N], hi_y[N], lo_z[N], hi_z[N];  ///< 24 N bytes of child bounds
    uint32_t child[N];

    static constexpr int kWidth = N;
    bool has_child(int c) const { return child[c] != kNoNode; }
    /// Child c's leaf primitive count; 0 for an inner or empty child.
    uint32_t leaf_count(int c) const { return has_child(c) ? ref_count(child[c]) : 0; }
    /// Child c decoded for traversals that keep the count beside it (packets): a leaf's
    /// first slot (or block), an inner child's node offset.
    uint32_t child_index(int c) const { return leaf_count(c) ? ref_first(child[c]) : child[c]; }
};
using Bvh8Node = BvhWideNode<8>;
static_assert(sizeof(Bvh8Node) == 256, "four cache lines per node");
static_assert(sizeof(Bvh8Node) % (kMaxWideLeafCount + 1) == 0,
              "node offsets keep the low bits of a reference 0");

/// An N-wide BVH. `root` keeps the root box; a leaf root has no nodes.
template <int N>
struct BvhWide {
    BvhNode root{};
    std::vector<BvhWideNode<N>, AlignedAllocator<BvhWideNode<N>, 64>>
        nodes;  ///< nodes[0]: the root's children
    bool empty = true;
    /// Any-hit traversal visits the hit children farthest entry first, not in slot order
    /// (traverse_wide). Rays that leave a surface inside an enclosure (a room) are mostly
    /// stopped by the far shell, not by what lies around their origin; set per tree by
    /// whoever knows which order suits it (Accelerator: OcclusionOrder).
    bool occlusion_far_first = false;

    /// An inner child holds its node's byte offset (index * sizeof(node)), not its
    /// index: the traversal's next node address is then one addition. The address
    /// depends on the node test just made, so a multiplication there would lengthen
    /// every step of the chain.
    static uint32_t offset_of(size_t index) { return uint32_t(index * sizeof(BvhWideNode<N>)); }
    static size_t index_of(uint32_t offset) { return offset / sizeof(BvhWideNode<N>); }
    const BvhWideNode<N>& node_at(uint32_t offset) const {
        return *reinterpret_cast<const BvhWideNode<N>*>(reinterpret_cast<const char*>(nodes.data()) + offset);
    }
    /// Offsets are 32-bit: at most 4 GiB of nodes (BVH8: 16.7M nodes, some 300M triangles).
    static constexpr size_t kMaxNodes = (size_t(1) << 32) / sizeof(BvhWideNode<N>);

    size_t bytes() const { return sizeof(BvhNode) + nodes.size() * sizeof(BvhWideNode<N>); }
};
using Bvh8 = BvhWide<8>;

/// Cost model of the collapse (bvh_wide.cpp): a wide node visit costs 1.
struct WideCollapse {
    /// A subtree of at most this many primitives (in contiguous slots) may become one
    /// leaf; 0 keeps the binary tree's leaves.
    uint32_t merge_leaves_up_to = 0;
    /// Cost of testing one leaf block of four primitives.
    double block_cost = 1.0;
    /// Binary trees with fewer nodes are solved on one thread (a parallel region costs
    /// more); the result is the same either way.
    size_t parallel_min_nodes = size_t(1) << 14;
};

/// Collapses a canonical binary Bvh (slots unchanged; nodes in depth-first order).
template <int N>
BvhWide<N> make_bvh_wide(const Bvh& bvh, const WideCollapse& opt = {});

}  // namespace sahara
