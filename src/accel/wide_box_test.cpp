// The per-ray constants of the FMA box test (Bvh8RayAvx), out of line (see there).
#include "accel/wide_box_test.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace sahara {

namespace {

/// A float at or above the real number whose round-to-nearest value is c: one step
/// of 2^-23 |c| is at least one ulp of c, the 2^-125 covers an underflowed product.
__attribute__((target("avx2,fma"), always_inline)) inline __m128 round_up(__m128 c) {
    const __m128 abs_c = _mm_and_ps(c, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)));
    return _mm_add_ps(_mm_fmadd_ps(abs_c, _mm_set1_ps(0x1p-23f), c), _mm_set1_ps(0x1p-125f));
}
/// A float at or below the real number whose round-to-nearest value is c.
__attribute__((target("avx2,fma"), always_inline)) inline __m128 round_down(__m128 c) {
    const __m128 abs_c = _mm_and_ps(c, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)));
    return _mm_sub_ps(_mm_fnmadd_ps(abs_c, _mm_set1_ps(0x1p-23f), c), _mm_set1_ps(0x1p-125f));
}

}  // namespace

__attribute__((target("avx2,fma"))) void Bvh8RayAvx::fma_box_constants(const BvhRay& r, float extent,
                                                                       float (*v)[4]) {
    // Lanes x, y, z; lane 3 holds the next member's bits and is never used.
    static_assert(offsetof(BvhRay, inv_dir) == offsetof(BvhRay, org) + 12 &&
                  offsetof(BvhRay, inv_far) == offsetof(BvhRay, inv_dir) + 12 &&
                  offsetof(BvhRay, neg) == offsetof(BvhRay, inv_far) + 12 &&
                  offsetof(BvhRay, tmin) == offsetof(BvhRay, neg) + 12);
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
    const __m128 sign =
        _mm_castsi128_ps(_mm_slli_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(r.neg)), 31));
    const __m128 org = _mm_loadu_ps(r.org);
    __m128 inv = _mm_loadu_ps(r.inv_dir);
    __m128 inv_far = _mm_loadu_ps(r.inv_far);
    const __m128 tiny = _mm_cmpgt_ps(_mm_and_ps(inv, abs_mask), _mm_set1_ps(kFmaBoxTinyInv));
    const __m128 ext = _mm_set1_ps(extent);
    __m128 range = _mm_mul_ps(_mm_add_ps(ext, _mm_and_ps(org, abs_mask)), _mm_and_ps(inv_far, abs_mask));
    const int tiny_axes = _mm_movemask_ps(tiny) & 7;
    if (tiny_axes) {
        inv = _mm_blendv_ps(inv, _mm_or_ps(_mm_set1_ps(kFmaBoxTinyInv), sign), tiny);
        inv_far =
            _mm_blendv_ps(inv_far, _mm_or_ps(_mm_set1_ps(kFmaBoxTinyInv * kRobustFarScale), sign), tiny);
        range = _mm_blendv_ps(range,
                              _mm_mul_ps(_mm_add_ps(ext, _mm_and_ps(org, abs_mask)),
                                         _mm_set1_ps(kFmaBoxTinyInv * kRobustFarScale)),
                              tiny);
    }
    __m128 c_n = round_up(_mm_mul_ps(org, inv));
    __m128 c_f = round_down(_mm_mul_ps(org, inv_far));
    if (tiny_axes) {
        // A hit point lies in the tree's box, so along the largest direction component
        // (the smallest inverse) it is at most (extent + |org|) / |d| away.
        float far = r.tmax, max_org = 0.0f, min_inv = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a) {
            max_org = std::max(max_org, std::fabs(r.org[a]));
            min_inv = std::min(min_inv, std::fabs(r.inv_dir[a]));
        }
        far = std::min(far, (extent + max_org) * min_inv);
        const __m128 t2 = _mm_set1_ps(4.0f * far);  // 2 T with T = 2 far: room for roundings
        c_f = _mm_blendv_ps(c_f, round_down(_mm_sub_ps(c_f, t2)), tiny);
        // A T too large (or NaN) switches those axes off.
        range = _mm_blendv_ps(range, _mm_max_ps(range, _mm_mul_ps(t2, _mm_set1_ps(0x1p1f))), tiny);
    }
    // Not <= (NaN compares false): such axes are switched off.
    const __m128 off = _mm_cmp_ps(range, _mm_set1_ps(kFmaBoxRange), _CMP_NLE_UQ);
    if (_mm_movemask_ps(off) & 7) {
        const float big = std::numeric_limits<float>::max();
        inv = _mm_blendv_ps(inv, _mm_or_ps(_mm_set1_ps(0x1p-100f), sign), off);
        inv_far = _mm_blendv_ps(inv_far, _mm_or_ps(_mm_set1_ps(0x1p-100f), sign), off);
        c_n = _mm_blendv_ps(c_n, _mm_set1_ps(big), off);
        c_f = _mm_blendv_ps(c_f, _mm_set1_ps(-big), off);
    }
    _mm_store_ps(v[0], inv);
    _mm_store_ps(v[1], inv_far);
    _mm_store_ps(v[2], c_n);
    _mm_store_ps(v[3], c_f);
}

}  // namespace sahara
