/// The exact SAH sweep of short ranges, branch-free where it can be: the centroid
/// orders are ranks counted over the three axes at once in SSE lanes (n(n-1) compares
/// for all three, where a sort's compares would mispredict about once per primitive),
/// and the children's areas are computed four split positions at a time.
#include "accel/bvh_small_sweep.h"

#include <algorithm>

namespace sahara::binned {

SmallSweep::SmallSweep(const PrimRef* refs, uint32_t n) : n_(n) {
    __m128 c[kSweepMaxPrims];
    __m128 nan = _mm_setzero_ps();
    for (uint32_t i = 0; i < n; ++i) {
        lo_[i] = load_lo(refs[i]);
        hi_[i] = _mm_load_ps(refs[i].hi);
        c[i] = _mm_load_ps(refs[i].c);
        nan = _mm_or_ps(nan, _mm_cmpunord_ps(c[i], c[i]));
    }
    valid_ = (_mm_movemask_ps(nan) & 7) == 0;  // NaNs compare false: ranks would collide
    // rank(j) on each axis = the primitives before j in centroid order, ties by index.
    for (uint32_t j = 0; j < n; ++j) {
        __m128i rank = _mm_setzero_si128();
        for (uint32_t i = 0; i < j; ++i)
            rank = _mm_sub_epi32(rank, _mm_castps_si128(_mm_cmple_ps(c[i], c[j])));
        for (uint32_t i = j + 1; i < n; ++i)
            rank = _mm_sub_epi32(rank, _mm_castps_si128(_mm_cmplt_ps(c[i], c[j])));
        alignas(16) uint32_t r[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(r), rank);
        for (int a = 0; a < 3; ++a) order_[a][r[a] & (kSweepMaxPrims - 1)] = uint8_t(j);
    }
}

SweepSplit SmallSweep::best(const SplitCosts& costs) const {
    SweepSplit best;
    if (!valid_) return best;
    const uint32_t n = n_;
    // Position k (1 <= k < n): the first k primitives left. Unused positions hold empty
    // boxes, so every group of four computes on initialised values.
    const uint32_t groups = (n + 3) / 4;
    alignas(16) float blk_left[kSweepMaxPrims], blk_right[kSweepMaxPrims], cost[kSweepMaxPrims];
    for (uint32_t k = 0; k < 4 * groups; ++k) {
        blk_left[k] = blocked_count(k, costs.leaf_block_size);
        blk_right[k] = k < n ? blocked_count(n - k, costs.leaf_block_size) : 0.0f;
    }
    const __m128 ic = _mm_set1_ps(costs.intersection_cost);
    for (int axis = 0; axis < 3; ++axis) {
        const uint8_t* o = order_[axis];
        __m128 llo[kSweepMaxPrims], lhi[kSweepMaxPrims], rlo[kSweepMaxPrims], rhi[kSweepMaxPrims];
        Box4 l, r;
        llo[0] = lhi[0] = rlo[0] = rhi[0] = _mm_setzero_ps();
        for (uint32_t k = n; k < 4 * groups; ++k) llo[k] = lhi[k] = rlo[k] = rhi[k] = _mm_setzero_ps();
        for (uint32_t k = 1; k < n; ++k) {
            l.extend(lo_[o[k - 1]], hi_[o[k - 1]]);
            r.extend(lo_[o[n - k]], hi_[o[n - k]]);
            llo[k] = l.lo, lhi[k] = l.hi;
            rlo[n - k] = r.lo, rhi[n - k] = r.hi;
        }
        for (uint32_t g = 0; g < groups; ++g) {
            const __m128 al = areas4(&llo[4 * g], &lhi[4 * g]), ar = areas4(&rlo[4 * g], &rhi[4 * g]);
            const __m128 sum = _mm_add_ps(_mm_mul_ps(al, _mm_load_ps(&blk_left[4 * g])),
                                          _mm_mul_ps(ar, _mm_load_ps(&blk_right[4 * g])));
            _mm_store_ps(&cost[4 * g], _mm_mul_ps(ic, sum));
        }
        for (uint32_t k = 1; k < n; ++k)
            if (cost[k] < best.cost) best = SweepSplit{axis, k, cost[k]};
    }
    return best;
}

void SmallSweep::apply(PrimRef* refs, const SweepSplit& s, Box4& left_box, Box4& right_box,
                       Box4& left_centroids, Box4& right_centroids) const {
    PrimRef copy[kSweepMaxPrims];
    std::copy_n(refs, n_, copy);
    const uint8_t* o = order_[s.axis];
    for (uint32_t k = 0; k < n_; ++k) {
        const PrimRef& p = copy[o[k]];
        refs[k] = p;
        Box4& box = k < s.left_count ? left_box : right_box;
        Box4& cent = k < s.left_count ? left_centroids : right_centroids;
        box.extend(lo_[o[k]], hi_[o[k]]);
        cent.extend(_mm_load_ps(p.c));
    }
}

}  // namespace sahara::binned
