#pragma once
/// Ordered traversal of a wide BVH: the hit children are sorted by entry distance and
/// visited nearest first, with the leaf tests a caller passes in (the Accelerator's
/// triangle blocks and other primitives, scene/trace_wide.inl).
#include <cstdint>
#include <utility>

#include "accel/bvh_traverse.h"
#include "accel/bvh_wide.h"
#include "accel/simd_path.h"
#include "accel/wide_box_test.h"

namespace sahara {

/// What a leaf test inside the traversal's inner loop found.
enum class LeafResult : uint8_t {
    miss,
    hit,   ///< a hit: `tmax` lowered (closest hit) or the search may end (any hit)
    slow,  ///< not decided and nothing changed: the leaf needs the full test
};

/// Ordered traversal of an N-wide BVH, with the contract of traverse_bvh
/// (bvh_traverse.h): the nearest hit child is visited next, the others are
/// pushed farthest first. Any-hit rays visit children in slot order instead, or
/// farthest entry first where the tree says so (BvhWide::occlusion_far_first).
/// kAvx: 8-wide box tests in AVX (caller compiled for AVX2); kAvx512: 8-wide nodes
/// take the AVX-512 step (intersect_bvh8_compress_avx512).
/// kPairNodes (8-wide; closest hit on the AVX2 and AVX-512 steps, any hit on the AVX2
/// step): until the first hit, the inner node on top of the stack is tested in the same
/// step as `cur`, and the hit children of both go to the stack together
/// (AcceleratorOptions::node_pairing).
///
/// Leaves go first to `fast_leaf`, which must call no function: the inner loop
/// then holds no call, and GCC keeps what of the ray's box constants fits in
/// registers there (the AVX2 build: the origins; the inverse directions are read
/// as memory operands). With a call anywhere in the loop it would keep them all on
/// the stack, every vector register being caller-saved. A leaf it answers `slow`
/// goes to `slow_leaf` (the complete test: other primitive kinds, the scalar
/// fallback, the alpha test) in the outer loop.
///
/// fast_leaf(first, count, next_first, next_count, paired, tmax) also gets the
/// stack entry that would be visited next (next_count 0: none, or an inner node);
/// when it tests that leaf in the same step it sets `paired`, and the entry is
/// dropped from the stack.
///
/// One long function on purpose (about 260 lines, against the 60 of the rest): the
/// node step, the child ordering and the leaf calls must sit in one inlined body
/// with no call in the inner loop (above); split into helpers that GCC does not
/// inline, the loop would spill the ray constants on every node.
template <bool kAnyHit, bool kAvx = false, bool kAvx512 = false, bool kPairNodes = false, int N,
          class Counters, class FastLeaf, class SlowLeaf>
__attribute__((always_inline)) inline bool traverse_wide(const BvhWide<N>& bvh, BvhRay& ray,
                                                         FastLeaf&& fast_leaf, SlowLeaf&& slow_leaf,
                                                         Counters& counters) {
    if (bvh.empty) return false;
    // No test of the root box: nodes[0] tests the root's children, which lie inside it.
    if (bvh.root.is_leaf()) {
        counters.on_prims(bvh.root.count);
        return slow_leaf(bvh.root.index, bvh.root.count, ray.tmax);
    }
    // A stack entry: a child reference and its entry distance, 8 bytes (the AVX-512 steps
    // write them as words: reference low, distance high).
    struct Entry {
        uint32_t ref;
        float t;
    };
    static_assert(sizeof(Entry) == 8);
    const char* const nodes = reinterpret_cast<const char*>(bvh.nodes.data());
    // Each node pushes at most N - 1 entries per level, plus slack. A paired step (any
    // kPairNodes form) pops one entry and pushes up to 2 N - 1, and pairs only while
    // top <= kPairMaxTop; above that the steps push N - 1 per level of one path down the
    // tree, so the stack stays below kPairMaxTop + 2 N + (N - 1) * kBvhMaxDepth.
    constexpr int kPairMaxTop = (N - 1) * kBvhMaxDepth;
    Entry stack[2 * (N - 1) * kBvhMaxDepth + 2 * N + 8];  // + 8: the AVX-512 any-hit step writes 8 entries
    int top = 0;
    bool found = false;
    Entry cur{0, ray.tmin};
    // tmax scaled for the far planes; changes only when a leaf lowers tmax.
    float tmax_far = ray.tmax * kRobustFarScale;
    // Inserts `in` among the entries pushed since `base`, which are sorted farthest deepest.
    auto push_sorted = [&](int base, Entry in) __attribute__((always_inline)) {
        int k = top++;
        while (k > base && stack[k - 1].t < in.t) {
            stack[k] = stack[k - 1];
            --k;
        }
        stack[k] = in;
    };
    // Puts the nearer of a and b into a without a branch: which of two hit children is
    // nearer is a coin toss for the predictor. Entry distances are at least tmin >= 0, so
    // their bit patterns order like the floats (were one negative, only the order of
    // visits would suffer, not the answer); on a tie, a stays.
    auto nearer_first = [](Entry & a, Entry & b) __attribute__((always_inline)) {
        const uint32_t ta = std::bit_cast<uint32_t>(a.t), tb = std::bit_cast<uint32_t>(b.t);
        const uint32_t swap = uint32_t(0) - uint32_t(tb < ta);
        const uint32_t dr = (a.ref ^ b.ref) & swap, dt = (ta ^ tb) & swap;
        a.ref ^= dr, b.ref ^= dr;
        a.t = std::bit_cast<float>(ta ^ dt), b.t = std::bit_cast<float>(tb ^ dt);
    };
    // Asks for the child boxes of the node at `p` (its first three cache lines; the fourth,
    // child links, is read only on a hit). The paired forms run on trees larger than the L2
    // cache (AcceleratorOptions::node_pairing), where a pushed node is often still in L3 or
    // memory when it is popped, so they prefetch every child they push. A leaf's reference
    // is not a node offset: that request is wasted, but it costs no branch (the address is
    // made in integers, as it may lie past the node array; a prefetch never faults).
    auto prefetch_planes = [nodes](uint32_t child) __attribute__((always_inline)) {
        const auto p = reinterpret_cast<const char*>(reinterpret_cast<uintptr_t>(nodes) + child);
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 64, _MM_HINT_T0);
        _mm_prefetch(p + 128, _MM_HINT_T0);
    };
    // The sort key of an any-hit entry visited farthest first (BvhWide::occlusion_far_first):
    // finite non-negative distances mapped to finite non-negative floats in reverse order,
    // so the nearest-first sorting below serves both orders. A ray's answer does not depend
    // on the order, only its cost.
    const bool far_first = kAnyHit && bvh.occlusion_far_first;
    auto far_key = [](float t) __attribute__((always_inline)) {
        return std::bit_cast<float>(0x7F7FFFFFu - std::bit_cast<uint32_t>(t));
    };
    // Pops the nearest pending entry that can still hold a closer hit into `cur`.
    auto pop = [&]() __attribute__((always_inline)) {
        for (;;) {
            if (top == 0) return false;
            cur = stack[--top];
            // An occlusion ray's tmax never shrinks: every pushed entry is still in reach.
            if (kAnyHit || cur.t <= tmax_far) return true;
        }
    };
    for (;;) {
        // Made here, not before the loop: their registers then never live across a call.
        const WideRay<N, kAvx && N == 8> rw(ray);
        for (;;) {  // the inner loop: no calls
            if (const uint32_t count = ref_count(cur.ref)) {
                counters.on_prims(count);
                // The entry visited next, when it is a leaf, may be tested in the same step.
                uint32_t next = 0;
                if (top > 0 && (kAnyHit || stack[top - 1].t <= tmax_far)) next = stack[top - 1].ref;
                bool paired = false;
                const LeafResult r =
                    fast_leaf(ref_first(cur.ref), count, ref_first(next), ref_count(next), paired, ray.tmax);
                if (r == LeafResult::slow) break;
                if (paired) {
                    --top;
                    counters.on_prims(ref_count(next));
                }
                if (r == LeafResult::hit) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                    tmax_far = ray.tmax * kRobustFarScale;
                }
            } else {
                const auto& n = *reinterpret_cast<const BvhWideNode<N>*>(nodes + cur.ref);  // node_at
                if constexpr (!std::is_same_v<Counters, NoTraversalCounters>)
                    for (int c = 0; c < N; ++c) counters.on_nodes(n.has_child(c) ? 1 : 0);
                if constexpr (kAvx512 && N == 8 && kAnyHit) {
                    if (far_first) {
                        alignas(32) uint32_t ref[N];
                        alignas(32) float t[N];
                        const Bvh8HitChildren h =
                            intersect_bvh8_compress_avx512(n, rw.avx, ray.tmin, tmax_far, ref, t);
                        if (!h.mask) {
                            if (!pop()) return found;
                            continue;
                        }
                        cur = Entry{h.ref0, far_key(h.t0)};
                        const int hits = __builtin_popcount(h.mask), base = top;
                        for (int i = 1; i < hits; ++i) {
                            Entry in{ref[i], far_key(t[i])};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        continue;
                    }
                    const Bvh8HitChildren h = intersect_bvh8_entries_avx512(
                        n, rw.avx, ray.tmin, tmax_far, reinterpret_cast<uint64_t*>(&stack[top]));
                    if (h.mask) {
                        // The first hit child is visited next, the others stay pushed (the
                        // last one on top); no branch on the number of hits.
                        cur = Entry{h.ref0, 0.0f};
                        top += __builtin_popcount(h.mask) - 1;
                        continue;
                    }
                    if (!pop()) return found;
                    continue;
                } else if constexpr (kAvx512 && N == 8) {  // closest hit
                    // Until the first hit, an inner node on top of the stack is tested in the
                    // same step (intersect_bvh8_pair_avx512): before a hit nothing culls it,
                    // so it is visited anyway, unless a hit below `cur` comes first.
                    if (kPairNodes && !found && top > 0 && top <= kPairMaxTop &&
                        ref_count(stack[top - 1].ref) == 0 && stack[top - 1].t <= tmax_far) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) uint64_t hit[2 * N];
                        const Bvh8HitChildren h =
                            intersect_bvh8_pair_avx512(n, b, rw.avx, ray.tmin, tmax_far, hit);
                        if (h.mask) {
                            cur = Entry{h.ref0, h.t0};
                            const int base = top;
                            for (int i = 1; i < int(h.mask); ++i) {
                                prefetch_planes(uint32_t(hit[i]));
                                Entry in = std::bit_cast<Entry>(hit[i]);
                                nearer_first(cur, in);
                                push_sorted(base, in);
                            }
                            continue;
                        }
                        if (!pop()) return found;
                        continue;
                    }
                    alignas(32) uint32_t ref[N];
                    alignas(32) float t[N];
                    const Bvh8HitChildren h =
                        intersect_bvh8_compress_avx512(n, rw.avx, ray.tmin, tmax_far, ref, t);
                    if (h.mask) {
                        cur = Entry{h.ref0, h.t0};
                        if (!(h.mask & (h.mask - 1))) continue;  // one child hit
                        const int hits = __builtin_popcount(h.mask);
                        const int base = top;
                        for (int i = 1; i < hits; ++i) {
                            if constexpr (kPairNodes) {
                                prefetch_planes(ref[i]);
                            }
                            Entry in{ref[i], t[i]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        continue;
                    }
                    if (!pop()) return found;
                    continue;
                }
                if constexpr (kPairNodes && kAvx && !kAvx512 && N == 8 && kAnyHit) {
                    // Occlusion rays on the AVX2 step pair nodes too (nothing culls a pushed
                    // entry): the hit children of both pushed in slot order, b's beneath, the
                    // last of a's visited next. (Not on the AVX-512 step: pairing cannot keep
                    // that step's first-hit-first order, without which its shadow rays are slower.)
                    if (!far_first && top > 0 && top <= kPairMaxTop && ref_count(stack[top - 1].ref) == 0) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) float ta[N], tb[N];
                        int ma = rw.test(n, ray.tmin, tmax_far, ta);
                        int mb = rw.test(b, ray.tmin, tmax_far, tb);
                        if (!(ma | mb)) {
                            if (!pop()) return found;
                            continue;
                        }
                        for (; mb; mb &= mb - 1)
                            stack[top++] = Entry{b.child[__builtin_ctz(unsigned(mb))], 0.0f};
                        for (; ma; ma &= ma - 1)
                            stack[top++] = Entry{n.child[__builtin_ctz(unsigned(ma))], 0.0f};
                        cur = stack[--top];
                        continue;
                    }
                }
                if constexpr (kPairNodes && kAvx && !kAvx512 && N == 8 && !kAnyHit) {
                    // The AVX2 form of the AVX-512 step's node pairing: both nodes' tests,
                    // then their hit children sorted into the stack as one batch.
                    if (!found && top > 0 && top <= kPairMaxTop && ref_count(stack[top - 1].ref) == 0 &&
                        stack[top - 1].t <= tmax_far) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) float ta[N], tb[N];
                        int ma = rw.test(n, ray.tmin, tmax_far, ta);
                        int mb = rw.test(b, ray.tmin, tmax_far, tb);
                        if (!(ma | mb)) {
                            if (!pop()) return found;
                            continue;
                        }
                        if (ma) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(ma)));
                            ma &= ma - 1;
                            cur = Entry{n.child[c], ta[c]};
                        } else {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(mb)));
                            mb &= mb - 1;
                            cur = Entry{b.child[c], tb[c]};
                        }
                        const int base = top;
                        for (; ma; ma &= ma - 1) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(ma)));
                            prefetch_planes(n.child[c]);
                            Entry in{n.child[c], ta[c]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        for (; mb; mb &= mb - 1) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(mb)));
                            prefetch_planes(b.child[c]);
                            Entry in{b.child[c], tb[c]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        continue;
                    }
                }
                alignas(32) float t[N];
                int mask = rw.test(n, ray.tmin, tmax_far, t);
                if (mask) {
                    // Unsigned: the child's address then needs no sign extension.
                    unsigned c = unsigned(__builtin_ctz(unsigned(mask)));
                    mask &= mask - 1;
                    cur = Entry{n.child[c], t[c]};
                    if (!mask) continue;  // one child hit: no ordering, no stack
                    if constexpr (kAnyHit) {
                        if (far_first) {
                            cur.t = far_key(cur.t);
                            const int base = top;
                            do {
                                c = unsigned(__builtin_ctz(unsigned(mask)));
                                mask &= mask - 1;
                                Entry in{n.child[c], far_key(t[c])};
                                nearer_first(cur, in);
                                push_sorted(base, in);
                            } while (mask);
                            continue;
                        }
                        // In slot order the search is cheapest when order buys little: push
                        // in child order (Embree's occlusion traversal does the same), the
                        // last becomes `cur`.
                        do {
                            stack[top++] = cur;
                            c = unsigned(__builtin_ctz(unsigned(mask)));
                            mask &= mask - 1;
                            cur = Entry{n.child[c], 0.0f};
                        } while (mask);
                        continue;
                    }
                    // Insert the others into the stack top sorted by distance (farthest
                    // deepest); the nearest of all becomes `cur`, without a branch as in
                    // the AVX-512 step (here a branch would be no faster).
                    const int base = top;
                    do {
                        c = unsigned(__builtin_ctz(unsigned(mask)));
                        mask &= mask - 1;
                        Entry in{n.child[c], t[c]};
                        nearer_first(cur, in);
                        push_sorted(base, in);
                    } while (mask);
                    continue;
                }
            }
            if (!pop()) return found;
        }
        if (slow_leaf(ref_first(cur.ref), ref_count(cur.ref), ray.tmax)) {
            if constexpr (kAnyHit) return true;
            found = true;
            tmax_far = ray.tmax * kRobustFarScale;
        }
        if (!pop()) return found;
    }
}

}  // namespace sahara
