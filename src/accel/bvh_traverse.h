#pragma once
/// Stack-based traversal of a binary Bvh: nearest child first, early out for
/// occlusion rays, leaf ranges handed to a caller-supplied functor.
///
/// Robustness: box tests use a precomputed inverse direction; a zero
/// direction component gives an infinite inverse, and the resulting
/// 0 * inf = NaN (origin exactly on a slab plane) is ignored by the min/max
/// order below, which treats that slab as unbounded, the conservative answer.
/// Following Ize, "Robust BVH Ray Traversal" (JCGT 2013), the far distance is
/// enlarged by 1 + 2 gamma(3) so rounding in the slab test never culls a box
/// the ray actually enters. The factor is folded into the inverse direction used
/// for far planes (inv_far): the far distance still goes through four roundings
/// (reciprocal, scaling, subtraction, product), as when the min is scaled after,
/// but the scaling leaves the per-node dependency chain.
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "accel/bvh.h"
#include "math/ray.h"

namespace sahara {

/// Marks "no node" in traversal.
inline constexpr uint32_t kNoNode = 0xFFFFFFFFu;

/// 1 + 2 gamma(3), gamma(n) = n eps / (1 - n eps), eps = 2^-24 (Ize 2013; pbrt-v3 sec. 3.9).
inline constexpr float kRobustFarScale = 1.0f + 2.0f * (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f);

/// Per-ray constants of the box test.
struct BvhRay {
    float org[3];
    float inv_dir[3];
    float inv_far[3];  ///< inv_dir * kRobustFarScale: far-plane distances come out enlarged
    int neg[3];        ///< 1 when the direction component is negative (also for -0): near plane is `hi`
    float tmin, tmax;

    explicit BvhRay(const Ray& r) : tmin(r.tmin), tmax(r.tmax) {
        const float d[3] = {load_scalar(r.dir.x), load_scalar(r.dir.y), load_scalar(r.dir.z)};
        org[0] = load_scalar(r.origin.x);
        org[1] = load_scalar(r.origin.y);
        org[2] = load_scalar(r.origin.z);
        for (int a = 0; a < 3; ++a) {
            inv_dir[a] = 1.0f / d[a];  // +-inf for +-0: handled in intersect_bvh_node
            inv_far[a] = inv_dir[a] * kRobustFarScale;
            neg[a] = std::signbit(d[a]) ? 1 : 0;
        }
    }
};

/// max/min that return the first argument when the second is NaN.
inline float max_ignore_nan(float acc, float x) { return x > acc ? x : acc; }
inline float min_ignore_nan(float acc, float x) { return x < acc ? x : acc; }

/// Slab test of one node box; on a hit `t_entry` is the (conservative) entry distance.
/// The reductions pair the axes as a tree (two steps deep, not three; the SIMD
/// tests use the same order, so every layout gives the same answers). Each step
/// keeps its first argument when the second is NaN; an inner step whose second
/// argument is NaN passes the NaN on, and the outer step then drops that pair,
/// which only widens the interval.
inline bool intersect_bvh_node(const BvhNode& n, const BvhRay& r, float& t_entry) {
    const float tx0 = (n.bounds[0 + r.neg[0]] - r.org[0]) * r.inv_dir[0];
    const float tx1 = (n.bounds[1 - r.neg[0]] - r.org[0]) * r.inv_far[0];
    const float ty0 = (n.bounds[2 + r.neg[1]] - r.org[1]) * r.inv_dir[1];
    const float ty1 = (n.bounds[3 - r.neg[1]] - r.org[1]) * r.inv_far[1];
    const float tz0 = (n.bounds[4 + r.neg[2]] - r.org[2]) * r.inv_dir[2];
    const float tz1 = (n.bounds[5 - r.neg[2]] - r.org[2]) * r.inv_far[2];
    const float t0 = max_ignore_nan(max_ignore_nan(r.tmin, tx0), max_ignore_nan(tz0, ty0));
    const float t1 = min_ignore_nan(min_ignore_nan(r.tmax * kRobustFarScale, tx1), min_ignore_nan(tz1, ty1));
    t_entry = t0;
    return t0 <= t1;
}

/// Per-ray traversal counters (only the counting variant of traversal pays for them).
struct TraversalCounters {
    uint64_t nodes_visited = 0;  ///< node boxes tested (root included)
    uint64_t prims_tested = 0;   ///< primitives handed to the leaf functor
    void on_nodes(uint32_t n) { nodes_visited += n; }
    void on_prims(uint32_t n) { prims_tested += n; }
    TraversalCounters& operator+=(const TraversalCounters& o) {
        nodes_visited += o.nodes_visited;
        prims_tested += o.prims_tested;
        return *this;
    }
};

/// Counter stand-in for the normal path: every call compiles to nothing.
struct NoTraversalCounters {
    void on_nodes(uint32_t) {}
    void on_prims(uint32_t) {}
};

/// Traverses `bvh` with `ray`; `leaf(first_slot, count, tmax)` tests bvh.prim_indices
/// [first_slot, first_slot + count), lowers `tmax` to its nearest hit, returns whether it
/// found one. kAnyHit stops at the first hit. Returns whether anything was hit. A traversal
/// kernel, over 60 lines on purpose: one loop keeps the ray's constants in registers.
template <bool kAnyHit, class Counters, class LeafFn>
bool traverse_bvh(const Bvh& bvh, BvhRay& ray, LeafFn&& leaf, Counters& counters) {
    if (bvh.nodes.empty()) return false;
    const BvhNode* nodes = bvh.nodes.data();
    float t_near = 0.0f, t_far = 0.0f;
    counters.on_nodes(1);
    if (!intersect_bvh_node(nodes[0], ray, t_near)) return false;
    if (nodes[0].is_leaf()) {
        counters.on_prims(nodes[0].count);
        return leaf(nodes[0].index, nodes[0].count, ray.tmax);
    }
    struct Entry {
        uint32_t node;
        float t_entry;
    };
    Entry stack[kBvhMaxDepth];
    int top = 0;
    bool found = false;
    uint32_t first = nodes[0].index;
    for (;;) {
        // Test both children; order them near, far.
        const BvhNode* a = &nodes[first];
        const BvhNode* b = &nodes[first + 1];
        counters.on_nodes(2);
        bool hit_a = intersect_bvh_node(*a, ray, t_near);
        bool hit_b = intersect_bvh_node(*b, ray, t_far);
        if (hit_b && (!hit_a || t_far < t_near)) {
            std::swap(a, b);
            std::swap(hit_a, hit_b);
            std::swap(t_near, t_far);
        }
        uint32_t next = kNoNode;
        if (hit_a) {
            if (a->is_leaf()) {
                counters.on_prims(a->count);
                if (leaf(a->index, a->count, ray.tmax)) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                }
            } else {
                next = a->index;
            }
        }
        if (hit_b && t_far <= ray.tmax * kRobustFarScale) {
            if (b->is_leaf()) {
                counters.on_prims(b->count);
                if (leaf(b->index, b->count, ray.tmax)) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                }
            } else if (next == kNoNode) {
                next = b->index;
            } else {
                stack[top++] = Entry{b->index, t_far};
            }
        }
        // Pop the nearest pending subtree that can still hold a closer hit.
        while (next == kNoNode) {
            if (top == 0) return found;
            const Entry e = stack[--top];
            if (e.t_entry <= ray.tmax * kRobustFarScale) next = e.node;
        }
        first = next;
    }
}

}  // namespace sahara
