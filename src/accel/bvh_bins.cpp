/// The split search of the binned builder: a sweep over each axis's non-empty bins
/// (near the leaves most bins are empty).
#include "accel/bvh_bins.h"

namespace sahara::binned {

namespace {

/// Bit b set where count[b] != 0, for b < nb (count has kMaxBins entries).
uint64_t nonzero_mask(const uint32_t* count, uint32_t nb) {
    uint64_t bits = 0;
    for (uint32_t b = 0; b < nb; b += 4) {
        const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(count + b));
        const auto zero =
            uint64_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(c, _mm_setzero_si128()))));
        bits |= (~zero & 15u) << b;
    }
    return nb == 64 ? bits : bits & ((uint64_t(1) << nb) - 1);
}

/// One axis at a time over its non-empty bins only: the boundaries between two of them
/// all cost the same, and the first of them (the one a sweep over every boundary keeps)
/// follows the left one.
BinSplit sparse_search(const Bins& bins, const BinMap& map, const SplitCosts& costs) {
    const uint32_t nb = map.count(), block = costs.leaf_block_size;
    BinSplit best;
    uint32_t used[kMaxBins];
    float right_area[kMaxBins];
    uint32_t right_count[kMaxBins];
    __m128 right_lo[kMaxBins], right_hi[kMaxBins];  // not cleared: written before read
    Box4 best_left, best_right;
    for (int axis = 0; axis < 3; ++axis) {
        if (!(map.scale_s[axis] > 0.0f)) continue;
        const Box4* box = bins.box[axis];
        const uint32_t* count = bins.count[axis];
        uint32_t m = 0;
        for (uint64_t bits = nonzero_mask(count, nb); bits; bits &= bits - 1)
            used[m++] = uint32_t(__builtin_ctzll(bits));
        if (m < 2) continue;
        Box4 acc;  // right_*[j]: bins used[j..m) together
        uint32_t cnt = 0;
        for (uint32_t j = m - 1; j > 0; --j) {
            acc.extend(box[used[j]]);
            cnt += count[used[j]];
            right_lo[j] = acc.lo;
            right_hi[j] = acc.hi;
            right_area[j] = acc.area();
            right_count[j] = cnt;
        }
        acc = Box4{};
        cnt = 0;
        for (uint32_t j = 1; j < m; ++j) {
            acc.extend(box[used[j - 1]]);
            cnt += count[used[j - 1]];
            const float cost =
                costs.intersection_cost * (acc.area() * blocked_count(cnt, block) +
                                           right_area[j] * blocked_count(right_count[j], block));
            if (cost < best.cost) {
                best.cost = cost;
                best.left_count = cnt;
                best.axis = axis;
                best.pos = used[j - 1] + 1;
                best_left = acc;
                best_right.lo = right_lo[j];
                best_right.hi = right_hi[j];
            }
        }
    }
    if (best.axis >= 0) best.left = best_left.bounds(), best.right = best_right.bounds();
    return best;
}

}  // namespace

BinSplit find_bin_split(const Bins& bins, const BinMap& map, const SplitCosts& costs) {
    return sparse_search(bins, map, costs);
}

}  // namespace sahara::binned
