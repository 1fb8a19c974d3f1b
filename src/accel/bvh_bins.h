#pragma once
/// Bins of the binned SAH builder (bvh_binned.cpp) and the search for the cheapest
/// bin boundary over them (bvh_bins.cpp). Internal to accel.
#include <emmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cstdint>

#include "math/bounds.h"

namespace sahara::binned {

inline constexpr uint32_t kMaxBins = 64;

/// A primitive as the builder moves it: box, id and centroid in three 16-byte lanes.
struct alignas(16) PrimRef {
    float lo[3];
    uint32_t id;
    float hi[3];
    float pad0;
    float c[3];
    float pad1;
};
static_assert(sizeof(PrimRef) == 48);

/// lo with lane 3 (the id's bits, often a denormal float: slow in arithmetic) cleared.
inline __m128 load_lo(const PrimRef& p) {
    return _mm_and_ps(_mm_load_ps(p.lo), _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}

/// A box in two SSE registers (lane 3 unused). The min/max argument order
/// matches std::min/std::max in Bounds3::extend, bit for bit.
struct Box4 {
    __m128 lo = _mm_set1_ps(kInfinity);
    __m128 hi = _mm_set1_ps(-kInfinity);

    void extend(__m128 l, __m128 h) {
        lo = _mm_min_ps(l, lo);
        hi = _mm_max_ps(h, hi);
    }
    void extend(__m128 p) { extend(p, p); }
    void extend(const Box4& b) { extend(b.lo, b.hi); }
    /// Bounds3::surface_area, the same operations in the same order.
    float area() const {
        if (_mm_movemask_ps(_mm_cmpgt_ps(lo, hi)) & 7) return 0.0f;
        const __m128 e = _mm_sub_ps(hi, lo);
        const __m128 yzx = _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1));
        const __m128 p = _mm_mul_ps(e, yzx);  // x*y, y*z, z*x
        const float sum = (_mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, 1))) +
                          _mm_cvtss_f32(_mm_shuffle_ps(p, p, 2));
        return 2.0f * sum;
    }
    Bounds3 bounds() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        return {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    }
};

/// Surface areas of four boxes (lane 3 of each ignored), Box4::area's operations in the
/// same order but four at a time; an empty box has area 0 as there, and a NaN extent
/// counts as 0.
inline __m128 areas4(const __m128* lo, const __m128* hi) {
    const __m128 zero = _mm_setzero_ps();
    __m128 e0 = _mm_max_ps(_mm_sub_ps(hi[0], lo[0]), zero), e1 = _mm_max_ps(_mm_sub_ps(hi[1], lo[1]), zero);
    __m128 e2 = _mm_max_ps(_mm_sub_ps(hi[2], lo[2]), zero), e3 = _mm_max_ps(_mm_sub_ps(hi[3], lo[3]), zero);
    _MM_TRANSPOSE4_PS(e0, e1, e2, e3);  // e0: x extents, e1: y, e2: z
    const __m128 sum = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, e1), _mm_mul_ps(e1, e2)), _mm_mul_ps(e2, e0));
    return _mm_add_ps(sum, sum);
}

/// Primitive count rounded up to whole leaf blocks of b (what a leaf of n actually tests).
inline float blocked_count(uint32_t n, uint32_t b) {
    if ((b & (b - 1)) == 0) return float((n + b - 1) & ~(b - 1));
    return float((n + b - 1) / b * b);
}

/// The bins of the three axes of one range (or of one chunk of it). Aligned so that
/// each bin's box (lo and hi, 32 bytes) is one aligned AVX load.
struct alignas(32) Bins {
    Box4 box[3][kMaxBins];
    uint32_t count[3][kMaxBins];

    void clear(uint32_t bins) {
        clear_counts(bins);
        for (int a = 0; a < 3; ++a)
            for (uint32_t k = 0; k < bins; ++k) box[a][k] = Box4{};
    }
    /// Zeroes the counts of bins [0, bins) in whole groups of four (a few stores, where
    /// std::fill_n calls memset for every small node).
    void clear_counts(uint32_t bins) {
        for (int a = 0; a < 3; ++a)
            for (uint32_t k = 0; k < bins; k += 4)
                _mm_storeu_si128(reinterpret_cast<__m128i*>(&count[a][k]), _mm_setzero_si128());
    }
    void add(const Bins& o, uint32_t bins) {
        for (int a = 0; a < 3; ++a)
            for (uint32_t k = 0; k < bins; ++k) box[a][k].extend(o.box[a][k]), count[a][k] += o.count[a][k];
    }
};

/// Maps centroids to bins: bin = clamp(int((c - lo) * scale), 0, bins - 1) per axis.
struct BinMap {
    __m128 lo, scale;
    float lo_s[3], scale_s[3];
    int last;

    BinMap(const Bounds3& centroids, uint32_t bins) : last(int(bins) - 1) {
        for (int a = 0; a < 3; ++a) {
            const float extent = centroids.hi[a] - centroids.lo[a];
            lo_s[a] = centroids.lo[a];
            scale_s[a] = extent > 0.0f ? float(bins) / extent : 0.0f;
        }
        lo = _mm_setr_ps(lo_s[0], lo_s[1], lo_s[2], 0.0f);
        scale = _mm_setr_ps(scale_s[0], scale_s[1], scale_s[2], 0.0f);
    }
    uint32_t count() const { return uint32_t(last) + 1; }
    uint32_t clamp(int b) const { return uint32_t(std::clamp(b, 0, last)); }
    /// The bins of centroid c on the three axes (lanes 0-2), clamped as clamp() does, in SSE2.
    __m128i bins(__m128 c, __m128i last_bin) const {
        __m128i k = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, lo), scale));
        k = _mm_and_si128(k, _mm_cmpgt_epi32(k, _mm_setzero_si128()));
        const __m128i over = _mm_cmpgt_epi32(k, last_bin);
        return _mm_or_si128(_mm_andnot_si128(over, k), _mm_and_si128(over, last_bin));
    }
    /// Bin on one axis (the same arithmetic as the three-axis version).
    uint32_t bin(const PrimRef& p, int axis) const { return bin_of(p.c[axis], axis); }
    uint32_t bin_of(float c, int axis) const {
        return clamp(_mm_cvtt_ss2si(_mm_set_ss((c - lo_s[axis]) * scale_s[axis])));
    }
};

/// Which side of bin boundary `pos` on `axis` a primitive falls on (left: bin < pos).
/// bin() is monotonic in the centroid over the range's centroid bounds when the extent and
/// the scale are finite, so there the test is one comparison against the smallest
/// centroid of the right side, found by bisection over the floats between the bounds (a
/// NaN centroid goes left either way: bin() clamps its integer conversion to 0). The
/// bisection starts from a few floats around the boundary's computed position, so it
/// costs about ten bin computations; shorter ranges than kThresholdMin bin instead.
class SideTest {
   public:
    static constexpr uint32_t kThresholdMin = 16;

    SideTest(const BinMap& map, int axis, uint32_t pos, float centroid_hi, uint32_t primitives)
        : map_(map), axis_(axis), pos_(pos) {
        if (primitives < kThresholdMin) return;
        const float lo = map.lo_s[axis];
        const float extent = centroid_hi - lo;
        if (!(extent <= kMaxFloat && map.scale_s[axis] <= kMaxFloat) || !(lo >= -kMaxFloat)) return;
        uint32_t a = key(lo), b = key(centroid_hi);  // bin(a) < pos <= bin(b)
        // Narrows [a, b] to a few floats around the boundary where the bins there confirm it
        // (rounding moves the boundary by a few floats at most); else the full bisection.
        const float guess = lo + float(pos) / map.scale_s[axis];
        if (guess > lo && guess < centroid_hi) {
            constexpr uint32_t kSlack = 4;
            const uint32_t g = key(guess);
            const uint32_t ga = g - std::min(kSlack, g - a), gb = g + std::min(kSlack, b - g);
            if (map.bin_of(from_key(ga), axis) < pos) a = ga;
            if (map.bin_of(from_key(gb), axis) >= pos) b = gb;
        }
        while (b - a > 1) {
            const uint32_t mid = a + (b - a) / 2;
            (map.bin_of(from_key(mid), axis) >= pos ? b : a) = mid;
        }
        threshold_ = from_key(b);
        by_threshold_ = true;
    }
    bool left(const PrimRef& p) const {
        return by_threshold_ ? !(p.c[axis_] >= threshold_) : map_.bin(p, axis_) < pos_;
    }

   private:
    /// Float to an unsigned key in the floats' order.
    static uint32_t key(float f) {
        uint32_t u;
        __builtin_memcpy(&u, &f, 4);
        return u & 0x80000000u ? ~u : u | 0x80000000u;
    }
    static float from_key(uint32_t k) {
        const uint32_t u = k & 0x80000000u ? k & 0x7fffffffu : ~k;
        float f;
        __builtin_memcpy(&f, &u, 4);
        return f;
    }
    static constexpr float kMaxFloat = 3.40282347e38f;

    const BinMap& map_;
    int axis_;
    uint32_t pos_;
    bool by_threshold_ = false;
    float threshold_ = 0.0f;
};

/// Clears the first map.count() bins of `out` and bins refs[begin, end) into them (the
/// AVX2 kernel where the active SIMD path allows, else SSE2; the same bins bit for bit).
/// Uses a thread's second set of bins for long ranges: not across a task scheduling point.
void fill_bins(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map, Bins& out);

/// A bin boundary and what it costs.
struct BinSplit {
    int axis = -1;
    uint32_t pos = 0;  ///< first bin of the right side
    float cost = kInfinity;
    uint32_t left_count = 0;
    Bounds3 left, right;
};

/// The SAH cost model as the split search needs it.
struct SplitCosts {
    float intersection_cost;
    uint32_t leaf_block_size;  ///< counts are rounded up to whole blocks
};

/// The cheapest bin boundary with primitives on both sides, over the axes with a non-zero
/// centroid extent; ties go to the lower axis, then to the lower boundary. Its cost is the
/// intersection term, intersection_cost * (area_left * blocked(n_left) + area_right * ...).
/// axis < 0: no such boundary. Reads only the boxes of non-empty bins.
BinSplit find_bin_split(const Bins& bins, const BinMap& map, const SplitCosts& costs);

}  // namespace sahara::binned
