/// The binning of the binned builder (SSE2 and AVX2 kernels) and its split search: a
/// sweep over each axis's non-empty bins (near the leaves most bins are empty).
#include "accel/bvh_bins.h"

#include <immintrin.h>

#include <climits>

#include "accel/simd_path.h"

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

/// Ranges binned into two sets of bins: the merge costs a few hundred instructions.
constexpr uint32_t kTwoBinSetsMin = 256;

/// A thread's second set of bins. Out of line: with -fPIC a thread_local access is a
/// call, which GCC repeated for every primitive of the loop, spilling its registers.
[[gnu::noinline]] Bins& odd_bins() {
    thread_local Bins bins;
    return bins;
}

void bin_one_sse2(const PrimRef& p, const BinMap& map, __m128i last, Bins& out) {
    alignas(16) uint32_t k[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(k), map.bins(_mm_load_ps(p.c), last));
    const __m128 lo = load_lo(p), hi = _mm_load_ps(p.hi);
    for (int a = 0; a < 3; ++a) {
        out.box[a][k[a]].extend(lo, hi);
        ++out.count[a][k[a]];
    }
}

/// Long ranges bin alternate primitives into two sets, merged at the end: neighbours
/// often share a bin, and one set would chain each box update to the store before it.
void fill_bins_sse2(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map, Bins& out) {
    const uint32_t bins = map.count();
    out.clear(bins);
    const __m128i last = _mm_set1_epi32(map.last);
    if (end - begin < kTwoBinSetsMin) {
        for (uint32_t i = begin; i < end; ++i) bin_one_sse2(refs[i], map, last, out);
        return;
    }
    Bins& odd = odd_bins();
    odd.clear(bins);
    uint32_t i = begin;
    for (; i + 1 < end; i += 2) {
        bin_one_sse2(refs[i], map, last, out);
        bin_one_sse2(refs[i + 1], map, last, odd);
    }
    if (i < end) bin_one_sse2(refs[i], map, last, out);
    out.add(odd, bins);
}

/// The AVX2 kernel keeps each bin's box as (lo, -hi) in one 256-bit register, so a single
/// min updates it (min(-a, -b) = -max(a, b), bit for bit, NaN and signed zero alike with
/// the same operand order), and clamps the three bin indices with one max and one min.
[[gnu::target("avx2")]] inline __m256 negate_hi(__m256 box) {
    return _mm256_xor_ps(box,
                         _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, 0, 0, INT_MIN, INT_MIN, INT_MIN, 0)));
}

[[gnu::target("avx2")]] inline float* bin_box(Bins& b, int axis, uint32_t k) {
    return reinterpret_cast<float*>(&b.box[axis][k]);
}

[[gnu::target("avx2")]] void clear_negated(Bins& out, uint32_t bins) {
    out.clear_counts(bins);
    const __m256 empty = _mm256_set1_ps(kInfinity);
    for (int a = 0; a < 3; ++a)
        for (uint32_t k = 0; k < bins; ++k) _mm256_store_ps(bin_box(out, a, k), empty);
}

[[gnu::target("avx2")]] inline void bin_one_avx2(const PrimRef& p, __m128 lo, __m128 scale, __m128i last,
                                                 Bins& out) {
    __m128i k = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(p.c), lo), scale));
    k = _mm_min_epi32(_mm_max_epi32(k, _mm_setzero_si128()), last);  // BinMap::bins' clamp
    // lo and hi of the record; lanes 3 and 7 (the id's bits, padding) cleared as load_lo does.
    const __m256 box = _mm256_blend_ps(negate_hi(_mm256_loadu_ps(p.lo)), _mm256_setzero_ps(), 0x88);
    alignas(16) uint32_t kk[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(kk), k);
    for (int a = 0; a < 3; ++a) {
        float* b = bin_box(out, a, kk[a]);
        _mm256_store_ps(b, _mm256_min_ps(box, _mm256_load_ps(b)));
        ++out.count[a][kk[a]];
    }
}

[[gnu::target("avx2")]] void fill_bins_avx2(const PrimRef* refs, uint32_t begin, uint32_t end,
                                            const BinMap& map, Bins& out) {
    const uint32_t bins = map.count();
    const __m128i last = _mm_set1_epi32(map.last);
    clear_negated(out, bins);
    if (end - begin < kTwoBinSetsMin) {
        for (uint32_t i = begin; i < end; ++i) bin_one_avx2(refs[i], map.lo, map.scale, last, out);
    } else {
        Bins& odd = odd_bins();
        clear_negated(odd, bins);
        uint32_t i = begin;
        for (; i + 1 < end; i += 2) {
            bin_one_avx2(refs[i], map.lo, map.scale, last, out);
            bin_one_avx2(refs[i + 1], map.lo, map.scale, last, odd);
        }
        if (i < end) bin_one_avx2(refs[i], map.lo, map.scale, last, out);
        for (int a = 0; a < 3; ++a)
            for (uint32_t k = 0; k < bins; ++k) {  // Bins::add's operand order
                float* b = bin_box(out, a, k);
                _mm256_store_ps(b, _mm256_min_ps(_mm256_load_ps(bin_box(odd, a, k)), _mm256_load_ps(b)));
                out.count[a][k] += odd.count[a][k];
            }
    }
    for (int a = 0; a < 3; ++a)
        for (uint32_t k = 0; k < bins; ++k)
            _mm256_store_ps(bin_box(out, a, k), negate_hi(_mm256_load_ps(bin_box(out, a, k))));
}

}  // namespace

void fill_bins(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map, Bins& out) {
    if (active_simd_path() == SimdPath::sse2)
        fill_bins_sse2(refs, begin, end, map, out);
    else
        fill_bins_avx2(refs, begin, end, map, out);
}

BinSplit find_bin_split(const Bins& bins, const BinMap& map, const SplitCosts& costs) {
    return sparse_search(bins, map, costs);
}

}  // namespace sahara::binned
