#pragma once
// The wide-BVH traversal body of Accelerator (trace_wide_body), compiled once per
// instruction set in a translation unit of its own: trace_wide_sse2.cpp,
// trace_wide_avx2.cpp and trace_wide_avx512.cpp. Each of those holds only its entry
// point and explicit instantiations, so an edit elsewhere in the accelerator cannot
// change the code GCC makes for the hot loop, and with it the loop's speed. Include only
// from those files.
#include "scene/accelerator.h"
#include "accel/bvh_wide.h"
#include "scene/leaf_blocks.inl"

namespace sahara {

/// The wide-BVH traversal; trace_wide_avx2 is the same code compiled for AVX2
/// (both inline this body, so each gets its own instruction selection; an
/// 8-wide node is tested in one AVX step there, as two SSE halves otherwise), and
/// trace_wide_avx512 for AVX-512 (kAvx512: its node step compresses the hit children).
template <bool kAnyHit, bool kCutouts, bool kBlocks, int N, bool kAvx, bool kAvx512, bool kPairNodes,
          class Counters>
__attribute__((always_inline)) inline bool Accelerator::trace_wide_body(const BvhWide<N>& tree, Ray& ray,
                                                                        Hit& hit, Counters& counters) const {
    // The triangle constants (axes and shear): a closest-hit ray that starts inside the
    // scene's bounds (a bounce) makes them before the first node, where the out-of-order
    // core overlaps them with the box tests. Other rays make them at their first leaf, as
    // many never reach one (shadow rays that are not blocked, camera rays from outside that
    // miss).
    BvhRay br(ray);
    TriangleRay tr;
    bool tr_ready = false;
    auto triangle_ray = [&]() __attribute__((always_inline))->const TriangleRay& {
        if (!tr_ready) {
            // Closest-hit rays are mostly bounces, occlusion rays mostly head for a light.
            // Only the AVX-512 body takes 1 / d[kz] from the box test's inverse direction:
            // the AVX2 body divides, which is faster there.
            tr = kAnyHit ? TriangleRay(ray) : TriangleRay::scattered(ray, kAvx512 ? br.inv_dir : nullptr);
            tr_ready = true;
        }
        return tr;
    };
    if constexpr (!kAnyHit)
        if (bounds_.contains(ray.origin)) triangle_ray();
    Hit best;
    const bool found = traverse_wide<kAnyHit, kAvx, kAvx512, kPairNodes>(
        tree, br,
        [&](uint32_t first, uint32_t count, uint32_t next_first, uint32_t next_count, bool& paired,
            float& tmax) __attribute__((always_inline)) {
            if constexpr (kBlocks)
                return test_blocks_fast<kAnyHit, kCutouts, kAvx>(ray, triangle_ray(), first, count,
                                                                 next_first, next_count, paired, tmax, best);
            else
                return LeafResult::slow;  // slots: every kind through the full test
        },
        [&](uint32_t first, uint32_t count, float& tmax) __attribute__((always_inline)) {
            if constexpr (kBlocks)
                return test_blocks<kAnyHit, kCutouts, kAvx>(ray, triangle_ray(), first, count, tmax, best);
            else
                return test_slots<kAnyHit, kCutouts>(ray, triangle_ray(), first, count, tmax, best);
        },
        counters);
    if (found && !kAnyHit) {
        hit = best;
        ray.tmax = best.t;
    }
    return found;
}

/// Calls M(kAnyHit, kCutouts, Counters) for every combination Accelerator::trace_layout
/// instantiates; each ISA's file defines M as the explicit instantiations of its entry point.
#define SAHARA_FOR_EACH_TRACE_FORM(M)                                        \
    M(false, false, NoTraversalCounters)                                     \
    M(false, true, NoTraversalCounters)                                      \
    M(true, false, NoTraversalCounters) M(true, true, NoTraversalCounters)   \
        M(false, false, TraversalCounters) M(false, true, TraversalCounters) \
            M(true, false, TraversalCounters) M(true, true, TraversalCounters)

}  // namespace sahara
