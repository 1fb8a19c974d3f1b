#pragma once
/// Traversal layout of a binary Bvh: one 64-byte block per inner node holding
/// both children's boxes (structure of arrays) and links, so one cache line
/// gives everything needed to test and order the two children. Converted from
/// the canonical Bvh after the build (builders, stats and validation use the
/// canonical form).
///
/// The two child boxes are tested together with SSE2, which every x86-64 CPU
/// has (no -march needed); other targets use a scalar path with the same
/// semantics. Robustness is that of bvh_traverse.h: NaN from 0 * inf (origin
/// on a slab plane, zero direction component) is ignored, and the far distance
/// is enlarged by 1 + 2 gamma(3) (Ize, "Robust BVH Ray Traversal", 2013).
#include <cstdint>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"

namespace sahara {

/// An inner node: per axis lo(child 0), lo(child 1), hi(child 0), hi(child 1).
struct alignas(64) BvhPairNode {
    float x[4], y[4], z[4];  ///< 48 bytes of child bounds
    uint32_t index[2];       ///< child c: inner -> its BvhPairNode index; leaf -> first primitive slot
    uint32_t count[2];       ///< child c: 0 for an inner node, else its primitive count; total 64 bytes
};
static_assert(sizeof(BvhPairNode) == 64, "one cache line per inner node");

/// A Bvh in pair layout. `root` keeps the root box; a leaf root has no pair nodes.
struct BvhPairs {
    BvhNode root{};
    std::vector<BvhPairNode, AlignedAllocator<BvhPairNode, 64>> nodes;  ///< nodes[0]: the root's children
    bool empty = true;

    size_t bytes() const { return sizeof(BvhNode) + nodes.size() * sizeof(BvhPairNode); }
};

/// Converts a canonical Bvh (depth-first order of the pair nodes; slots unchanged).
BvhPairs make_bvh_pairs(const Bvh& bvh);

/// Tests both children of `n`; bit c of the result is set when child c is hit,
/// and t_near[c] is then its entry distance. Same answers as intersect_bvh_node.
inline int intersect_bvh_pair(const BvhPairNode& n, const BvhRay& r, float t_near[2]) {
#if defined(__SSE2__)
    // Lanes of one axis after the sign fix-up: near(c0), near(c1), far(c0), far(c1);
    // far lanes use the enlarged inverse direction (BvhRay::inv_far).
    auto axis = [](const float* b, float org, float inv, float inv_far, int neg) {
        const __m128 scale = _mm_set_ps(inv_far, inv_far, inv, inv);
        const __m128 p = _mm_load_ps(b);
        // With a negative direction the near planes are the `hi` lanes: swap before scaling.
        const __m128 planes = neg ? _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 0, 3, 2)) : p;
        return _mm_mul_ps(_mm_sub_ps(planes, _mm_set1_ps(org)), scale);
    };
    // Negating the far lanes turns min(far) into max(-far): one max per step, in the
    // order of intersect_bvh_node (_mm_max_ps(x, acc) returns acc when x is NaN).
    const __m128 negate_far = _mm_set_ps(-0.0f, -0.0f, 0.0f, 0.0f);
    const float tmax = r.tmax * kRobustFarScale;
    const __m128 init = _mm_set_ps(-tmax, -tmax, r.tmin, r.tmin);
    const __m128 x = _mm_xor_ps(axis(n.x, r.org[0], r.inv_dir[0], r.inv_far[0], r.neg[0]), negate_far);
    const __m128 y = _mm_xor_ps(axis(n.y, r.org[1], r.inv_dir[1], r.inv_far[1], r.neg[1]), negate_far);
    const __m128 z = _mm_xor_ps(axis(n.z, r.org[2], r.inv_dir[2], r.inv_far[2], r.neg[2]), negate_far);
    const __m128 acc = _mm_max_ps(_mm_max_ps(y, z), _mm_max_ps(x, init));
    const __m128 far = _mm_xor_ps(_mm_shuffle_ps(acc, acc, _MM_SHUFFLE(3, 2, 3, 2)), _mm_set1_ps(-0.0f));
    alignas(16) float out[4];
    _mm_store_ps(out, acc);
    t_near[0] = out[0];
    t_near[1] = out[1];
    return _mm_movemask_ps(_mm_cmple_ps(acc, far)) & 3;
#else
    int mask = 0;
    for (int c = 0; c < 2; ++c) {
        const float* b[3] = {n.x, n.y, n.z};
        float tn[3], tf[3];
        for (int a = 0; a < 3; ++a) {
            tn[a] = (b[a][c + 2 * r.neg[a]] - r.org[a]) * r.inv_dir[a];
            tf[a] = (b[a][c + 2 - 2 * r.neg[a]] - r.org[a]) * r.inv_far[a];
        }
        const float t0 = max_ignore_nan(max_ignore_nan(r.tmin, tn[0]), max_ignore_nan(tn[2], tn[1]));
        const float t1 =
            min_ignore_nan(min_ignore_nan(r.tmax * kRobustFarScale, tf[0]), min_ignore_nan(tf[2], tf[1]));
        t_near[c] = t0;
        if (t0 <= t1) mask |= 1 << c;
    }
    return mask;
#endif
}

/// Traversal over the pair layout, with the contract of traverse_bvh (bvh_traverse.h).
template <bool kAnyHit, class Counters, class LeafFn>
bool traverse_bvh_pairs(const BvhPairs& bvh, BvhRay& ray, LeafFn&& leaf, Counters& counters) {
    if (bvh.empty) return false;
    float t_root = 0.0f;
    counters.on_nodes(1);
    if (!intersect_bvh_node(bvh.root, ray, t_root)) return false;
    if (bvh.root.is_leaf()) {
        counters.on_prims(bvh.root.count);
        return leaf(bvh.root.index, bvh.root.count, ray.tmax);
    }
    struct Entry {
        uint32_t node;
        float t_entry;
    };
    Entry stack[kBvhMaxDepth];
    int top = 0;
    bool found = false;
    uint32_t cur = 0;
    for (;;) {
        const BvhPairNode& n = bvh.nodes[cur];
        counters.on_nodes(2);
        float t[2];
        const int mask = intersect_bvh_pair(n, ray, t);
        // Near child first: c0 is the nearer hit child, c1 the other.
        const int c0 = (mask == 3 && t[1] < t[0]) || mask == 2 ? 1 : 0, c1 = 1 - c0;
        const bool hit1 = mask == 3;
        uint32_t next = kNoNode;
        if (mask) {
            if (n.count[c0]) {
                counters.on_prims(n.count[c0]);
                if (leaf(n.index[c0], n.count[c0], ray.tmax)) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                }
            } else {
                next = n.index[c0];
            }
        }
        if (hit1 && t[c1] <= ray.tmax * kRobustFarScale) {
            if (n.count[c1]) {
                counters.on_prims(n.count[c1]);
                if (leaf(n.index[c1], n.count[c1], ray.tmax)) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                }
            } else if (next == kNoNode) {
                next = n.index[c1];
            } else {
                stack[top++] = Entry{n.index[c1], t[c1]};
            }
        }
        while (next == kNoNode) {
            if (top == 0) return found;
            const Entry e = stack[--top];
            if (e.t_entry <= ray.tmax * kRobustFarScale) next = e.node;
        }
        cur = next;
    }
}

}  // namespace sahara
