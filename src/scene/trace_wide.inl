#pragma once
// The wide8 traversal body of Accelerator (trace_wide_body), compiled once per
// instruction set in a translation unit of its own: trace_wide_sse2.cpp,
// trace_wide_avx2.cpp and trace_wide_avx512.cpp. Each of those holds only its entry
// point and the table that emits its forms (trace_form_table), so an edit elsewhere in
// the accelerator cannot change the code GCC makes for the hot loop, and with it the
// loop's speed. Include only from those files.
#include <new>
#include <tuple>
#include <type_traits>
#include <utility>

#include "scene/accelerator.h"
#include "accel/traverse_wide.h"
#include "scene/leaf_blocks.inl"

namespace sahara {

/// The wide8 traversal; trace_wide_avx2 is the same code compiled for AVX2
/// (both inline this body, so each gets its own instruction selection; an
/// 8-wide node is tested in one AVX step there, as two SSE halves otherwise), and
/// trace_wide_avx512 for AVX-512 (kAvx512: its node step compresses the hit children).
template <bool kAnyHit, bool kCutouts, bool kAvx, bool kAvx512, bool kPairNodes, class Counters>
__attribute__((always_inline)) inline bool Accelerator::trace_wide_body(Ray& ray, Hit& hit,
                                                                        Counters& counters) const {
    // The triangle constants (axes and shear): a closest-hit ray that starts inside the
    // scene's bounds (a bounce) makes them before the first node, where the out-of-order
    // core overlaps them with the box tests. Other rays make them at their first leaf, as
    // many never reach one (shadow rays that are not blocked, camera rays from outside that
    // miss).
    BvhRay br(ray);
    // Storage only: TriangleRay's member defaults would be stores that every ray pays
    // before its first node and that many never read.
    union LazyTriangleRay {
        LazyTriangleRay() {}
        TriangleRay tr;
    } lazy;
    bool tr_ready = false;
    auto triangle_ray = [&]() __attribute__((always_inline))->const TriangleRay& {
        if (!tr_ready) {
            // Closest-hit rays are mostly bounces, occlusion rays mostly head for a light.
            // Only the AVX-512 body takes 1 / d[kz] from the box test's inverse direction:
            // the AVX2 body divides, which is faster there.
            new (&lazy.tr) TriangleRay(kAnyHit ? TriangleRay(ray)
                                               : TriangleRay::scattered(ray, kAvx512 ? br.inv_dir : nullptr));
            tr_ready = true;
        }
        return lazy.tr;
    };
    if constexpr (!kAnyHit)
        if (bounds_.contains(ray.origin)) triangle_ray();
    Hit best;
    const bool found = traverse_wide<kAnyHit, kAvx, kAvx512, kPairNodes>(
        wide8_, br,
        [&](uint32_t first, uint32_t count, uint32_t next_first, uint32_t next_count, bool& paired,
            float& tmax) __attribute__((always_inline)) {
            return test_blocks_fast<kAnyHit, kCutouts, kAvx>(ray, triangle_ray(), first, count, next_first,
                                                             next_count, paired, tmax, best);
        },
        [&](uint32_t first, uint32_t count, float& tmax) __attribute__((always_inline)) {
            return test_blocks<kAnyHit, kCutouts, kAvx>(ray, triangle_ray(), first, count, tmax, best);
        },
        counters);
    if (found && !kAnyHit) {
        hit = best;
        ray.tmax = best.t;
    }
    if (found && kAnyHit) hit.prim = best.prim;  // the occluder's block (OcclusionCache)
    return found;
}

/// One form of the traversal, by index: bit 0 kAnyHit, bit 1 kCutouts, bit 2 counted
/// (TraversalCounters), bit 3 kPairNodes. Forms [0, kTraceForms) are every combination
/// Accelerator::trace_layout calls; the SSE2 path, which never pairs nodes, only the first half.
template <unsigned kForm>
struct TraceForm {
    static constexpr bool kAnyHit = (kForm & 1) != 0;
    static constexpr bool kCutouts = (kForm & 2) != 0;
    using Counters = std::conditional_t<(kForm & 4) != 0, TraversalCounters, NoTraversalCounters>;
    static constexpr bool kPairNodes = (kForm & 8) != 0;
};
inline constexpr unsigned kTraceForms = 16;
inline constexpr unsigned kUnpairedTraceForms = 8;

/// The addresses of instruction set kPath's entry point for forms [0, kCount)
/// (TraceWideEntry<kPath, Form>::ptr). Each ISA's file keeps them in a [[gnu::used]]
/// constant, which makes the compiler emit every form there; the other files only
/// declare the entry points and call them.
template <SimdPath kPath, unsigned... kForms>
constexpr auto trace_form_table(std::integer_sequence<unsigned, kForms...>) {
    return std::tuple{TraceWideEntry<kPath, TraceForm<kForms>>::ptr...};
}

}  // namespace sahara
