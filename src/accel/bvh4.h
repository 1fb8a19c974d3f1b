#pragma once
/// A 4-wide BVH (BVH4) collapsed from the binary SAH tree: each node holds the
/// boxes of up to four children in structure-of-arrays form (one 128-byte
/// block: 96 bytes of bounds, 32 bytes of links), so one ray tests all four
/// children in one SSE step. Collapsing follows the usual "open the largest
/// inner child" rule (Wald, Benthin and Boulos, "Getting Rid of Packets",
/// 2008; Dammertz et al., "Shallow Bounding Volume Hierarchies", 2008).
///
/// Traversal is ordered: the hit children are sorted by entry distance and
/// visited nearest first. Robustness is that of bvh_traverse.h: NaN from
/// 0 * inf (origin on a slab plane, zero direction component) is ignored, and
/// the far distance is enlarged by 1 + 2 gamma(3) (Ize, "Robust BVH Ray
/// Traversal", 2013). Unused child slots hold an empty box (lo = +inf,
/// hi = -inf), which no ray with a finite origin can hit.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include <emmintrin.h>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"

namespace sahara {

/// One BVH4 node; child c is empty (child[c] == kNoNode, count 0), inner
/// (count 0, child = node index) or a leaf (count > 0, child = first slot).
struct alignas(64) Bvh4Node {
    float lo_x[4], hi_x[4], lo_y[4], hi_y[4], lo_z[4], hi_z[4];  ///< 96 bytes of child bounds
    uint32_t child[4];
    uint32_t count[4];

    bool has_child(int c) const { return child[c] != kNoNode; }
};
static_assert(sizeof(Bvh4Node) == 128, "two cache lines per node");

/// A BVH4. `root` keeps the root box; a leaf root has no nodes.
struct Bvh4 {
    BvhNode root{};
    std::vector<Bvh4Node, AlignedAllocator<Bvh4Node, 64>> nodes;  ///< nodes[0]: the root's children
    bool empty = true;

    size_t bytes() const { return sizeof(BvhNode) + nodes.size() * sizeof(Bvh4Node); }
};

/// Collapses a canonical binary Bvh (slots unchanged; nodes in depth-first order).
Bvh4 make_bvh4(const Bvh& bvh);

/// Which instruction set the BVH4 traversal uses.
enum class SimdPath : uint8_t {
    sse2,  ///< baseline of every x86-64 CPU
    avx2,  ///< the same traversal compiled for AVX2 (VEX encoding), chosen at run time
};

/// The path in use: AVX2 when the CPU has it, unless SAHARA_SIMD=sse2 is set
/// in the environment or force_simd_path() was called.
SimdPath active_simd_path();
/// Forces a path (tests; an AVX2 request on a CPU without AVX2 falls back to SSE2).
void force_simd_path(SimdPath path);
/// Whether this CPU can run the AVX2 path.
bool cpu_has_avx2();
/// "sse2" or "avx2".
const char* simd_path_name(SimdPath path);

/// Per-ray constants of the BVH4 box test: broadcast origin and inverse
/// direction, and the byte offsets of each axis's near and far planes in a node.
struct Bvh4Ray {
    __m128 org[3], inv[3];
    uint32_t near_off[3], far_off[3];

    explicit Bvh4Ray(const BvhRay& r) {
        const uint32_t lo[3] = {offsetof(Bvh4Node, lo_x), offsetof(Bvh4Node, lo_y), offsetof(Bvh4Node, lo_z)};
        const uint32_t hi[3] = {offsetof(Bvh4Node, hi_x), offsetof(Bvh4Node, hi_y), offsetof(Bvh4Node, hi_z)};
        for (int a = 0; a < 3; ++a) {
            org[a] = _mm_set1_ps(r.org[a]);
            inv[a] = _mm_set1_ps(r.inv_dir[a]);
            // Near plane of an axis is `hi` for a negative direction.
            near_off[a] = r.neg[a] ? hi[a] : lo[a];
            far_off[a] = r.neg[a] ? lo[a] : hi[a];
        }
    }
};

/// Tests the four children of `n`; bit c of the result is set when child c is
/// hit, and lane c of t_near is then its entry distance. Same answers as
/// intersect_bvh_node per child.
__attribute__((always_inline)) inline int intersect_bvh4(const Bvh4Node& n, const Bvh4Ray& r, float tmin,
                                                         float tmax, __m128& t_near) {
    // _mm_max_ps(x, acc) and _mm_min_ps(x, acc) return acc when x is NaN (the NaN-ignoring order).
    __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
    const char* base = reinterpret_cast<const char*>(&n);
    for (int a = 0; a < 3; ++a) {
        const __m128 near = _mm_load_ps(reinterpret_cast<const float*>(base + r.near_off[a]));
        const __m128 far = _mm_load_ps(reinterpret_cast<const float*>(base + r.far_off[a]));
        t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near, r.org[a]), r.inv[a]), t0);
        t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(far, r.org[a]), r.inv[a]), t1);
    }
    t_near = t0;
    return _mm_movemask_ps(_mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(kRobustFarScale))));
}

/// Ordered traversal of a BVH4, with the contract of traverse_bvh (bvh_traverse.h):
/// the nearest hit child is visited next, the others are pushed farthest first.
template <bool kAnyHit, class Counters, class LeafFn>
__attribute__((always_inline)) inline bool traverse_bvh4(const Bvh4& bvh, BvhRay& ray, LeafFn&& leaf,
                                                         Counters& counters) {
    if (bvh.empty) return false;
    float t_root = 0.0f;
    counters.on_nodes(1);
    if (!intersect_bvh_node(bvh.root, ray, t_root)) return false;
    if (bvh.root.is_leaf()) {
        counters.on_prims(bvh.root.count);
        return leaf(bvh.root.index, bvh.root.count, ray.tmax);
    }
    struct Entry {
        uint32_t index;  ///< node index, or first leaf item
        uint32_t count;  ///< 0: inner node
        float t_entry;
    };
    const Bvh4Ray r4(ray);
    // Each node pushes at most three entries: 3 per level plus slack.
    Entry stack[3 * kBvhMaxDepth + 4];
    int top = 0;
    bool found = false;
    Entry cur{0, 0, t_root};
    for (;;) {
        if (cur.count) {
            counters.on_prims(cur.count);
            if (leaf(cur.index, cur.count, ray.tmax)) {
                if constexpr (kAnyHit) return true;
                found = true;
            }
        } else {
            const Bvh4Node& n = bvh.nodes[cur.index];
            if constexpr (!std::is_same_v<Counters, NoTraversalCounters>)
                for (int c = 0; c < 4; ++c) counters.on_nodes(n.has_child(c) ? 1 : 0);
            __m128 tv;
            int mask = intersect_bvh4(n, r4, ray.tmin, ray.tmax, tv);
            if (mask) {
                alignas(16) float t[4];
                _mm_store_ps(t, tv);
                int c = __builtin_ctz(unsigned(mask));
                mask &= mask - 1;
                cur = Entry{n.child[c], n.count[c], t[c]};
                if (!mask) continue;  // one child hit: no ordering, no stack
                // Insert the others into the stack top sorted by distance (farthest
                // deepest); the nearest of all becomes `cur`.
                const int base = top;
                do {
                    c = __builtin_ctz(unsigned(mask));
                    mask &= mask - 1;
                    Entry in{n.child[c], n.count[c], t[c]};
                    if (in.t_entry < cur.t_entry) std::swap(in, cur);
                    int k = top++;
                    while (k > base && stack[k - 1].t_entry < in.t_entry) {
                        stack[k] = stack[k - 1];
                        --k;
                    }
                    stack[k] = in;
                } while (mask);
                continue;
            }
        }
        // Pop the nearest pending entry that can still hold a closer hit.
        for (;;) {
            if (top == 0) return found;
            cur = stack[--top];
            if (cur.t_entry <= ray.tmax * kRobustFarScale) break;
        }
    }
}

}  // namespace sahara
