#include "accel/crossings.h"

#include "accel/bvh_traverse.h"
#include "accel/simd_path.h"
#include "accel/traverse_wide.h"

namespace sahara {

namespace {

/// Calls on_hit(Hit) for every crossing of `ray` in (tmin, tmax). The any-hit form of
/// the wide traversal never culls a pushed child by distance, and no leaf here reports
/// a hit, so every leaf whose box the ray enters is visited and tmax never shrinks.
///
/// The fast leaf (no call, see traverse_wide) tests one- and two-block leaves with the
/// SIMD step, whose lanes without an exactly-zero edge function need no tie-break.
/// A leaf with a lane the SIMD step leaves to the scalar test, other primitive kinds or more blocks goes to
/// the slow leaf, which tests it with the EdgesPerturbed tie-break; so does every leaf with a crossing unless
/// kCountInFastLeaf (a count needs no hit record, only the number).
template <bool kAvx, bool kCountInFastLeaf, class OnHit>
__attribute__((always_inline)) inline void walk_crossings(const Bvh8& tree,
                                                          std::span<const TriangleBlock4> blocks,
                                                          const Ray& ray, uint32_t& fast_count,
                                                          OnHit&& on_hit) {
    BvhRay box_ray(ray);
    const TriangleRay tr = TriangleRay::scattered(ray, nullptr);
    const float tmin = ray.tmin, tmax = ray.tmax;
    const TriangleBlock4* const block = blocks.data();
    auto fast_leaf = [&](uint32_t first, uint32_t count, uint32_t, uint32_t, bool&, float&)
        __attribute__((always_inline)) {
        if (count > 8) return LeafResult::slow;
        const TriangleBlock4* b = block + first;
        const bool two = count > 4;
        if (other_lanes(b[0]) | (two ? other_lanes(b[1]) : 0)) return LeafResult::slow;
        alignas(32) float t[8], u[8], v[8];
        int scalar_lanes = 0, mask = 0;
        if (kAvx && two) {
            mask = intersect_triangle_blocks2_avx_simd(tr, b, b + 1, tmin, tmax, t, u, v, scalar_lanes);
        } else {
            mask = intersect_triangle_block4_simd(tr, b[0], tmin, tmax, t, u, v, scalar_lanes);
            if (two && !scalar_lanes)
                mask |=
                    intersect_triangle_block4_simd(tr, b[1], tmin, tmax, t + 4, u + 4, v + 4, scalar_lanes)
                    << 4;
        }
        if (scalar_lanes || (!kCountInFastLeaf && mask)) return LeafResult::slow;
        fast_count += uint32_t(__builtin_popcount(unsigned(mask)));
        return LeafResult::miss;
    };
    auto slow_leaf = [&](uint32_t first, uint32_t count, float&) __attribute__((always_inline)) {
        const uint32_t end = first + (count + 3) / 4;
        for (uint32_t b = first; b < end; ++b) {
            if (other_lanes(block[b]) == 0xF) continue;
            alignas(16) float t[4], u[4], v[4];
            // intersect_triangle_block4 with the crossings' tie-break in the scalar redo.
            int scalar_lanes = 0;
            int mask = intersect_triangle_block4_simd(tr, block[b], tmin, tmax, t, u, v, scalar_lanes);
            if (scalar_lanes)
                mask |= redo_scalar_lanes<EdgesPerturbed>(tr, block[b], scalar_lanes, 0, tmin, tmax, t, u, v);
            for (; mask; mask &= mask - 1) {
                const int l = __builtin_ctz(unsigned(mask));
                on_hit(Hit{t[l], block[b].slot[l], u[l], v[l]});
            }
        }
        return false;  // keeps tmax and the traversal going
    };
    NoTraversalCounters counters;
    traverse_wide<true, kAvx, false, kAvx>(tree, box_ray, fast_leaf, slow_leaf, counters);
}

template <bool kCountInFastLeaf, class OnHit>
void walk_crossings_sse2(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                         uint32_t& fast_count, OnHit&& on_hit) {
    walk_crossings<false, kCountInFastLeaf>(tree, blocks, ray, fast_count, on_hit);
}

/// The same walk compiled for AVX2: 8-wide node tests, two leaf blocks in one step, and
/// node pairing as occlusion rays have it (nothing culls a pushed node here either).
template <bool kCountInFastLeaf, class OnHit>
__attribute__((target("avx2"))) void walk_crossings_avx2(const Bvh8& tree,
                                                         std::span<const TriangleBlock4> blocks,
                                                         const Ray& ray, uint32_t& fast_count,
                                                         OnHit&& on_hit) {
    walk_crossings<true, kCountInFastLeaf>(tree, blocks, ray, fast_count, on_hit);
}

template <bool kCountInFastLeaf, class OnHit>
uint32_t for_each_crossing(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                           OnHit&& on_hit) {
    uint32_t fast_count = 0;
    if (active_simd_path() == SimdPath::sse2)
        walk_crossings_sse2<kCountInFastLeaf>(tree, blocks, ray, fast_count, on_hit);
    else
        walk_crossings_avx2<kCountInFastLeaf>(tree, blocks, ray, fast_count, on_hit);
    return fast_count;
}

}  // namespace

void collect_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                       std::vector<Hit>& out) {
    if (blocks.empty()) return;
    for_each_crossing<false>(tree, blocks, ray, [&](const Hit& h) { out.push_back(h); });
}

uint32_t count_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray) {
    if (blocks.empty()) return 0;
    uint32_t slow_count = 0;
    return for_each_crossing<true>(tree, blocks, ray, [&](const Hit&) { ++slow_count; }) + slow_count;
}

}  // namespace sahara
