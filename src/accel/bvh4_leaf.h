#pragma once
/// Wide-BVH leaves as blocks of four triangles in structure-of-arrays form, tested
/// with SSE four at a time by the watertight test of Woop, Benthin and Wald
/// ("Watertight Ray/Triangle Intersection", JCGT 2013). Every lane performs
/// exactly the float operations of TriangleVerts::intersect (geometry/triangle.h),
/// in the same order and without fused multiply-adds, so the answers are
/// bit-identical. Two kinds of lanes are redone by the scalar test, which falls back
/// to double for them: an edge function of exactly 0 (as the paper requires), and a
/// hit whose t is within its rounding bound of 0 (it may lie behind the origin;
/// t_scaled_error_bound). Only the first kind can depend on the tie-break policy
/// (geometry/triangle.h), so the scalar redo takes it as a parameter and the SIMD
/// steps need none.
///
/// Lanes that hold no triangle (another primitive kind, or padding) have NaN
/// vertices, which every comparison rejects; the caller tests those kinds itself.
///
/// With AVX2, two consecutive blocks are tested in one 8-lane step
/// (intersect_triangle_blocks2_avx): the same operations per lane, so the
/// storage stays one format for every ISA.
#include <cstdint>

#include <immintrin.h>

#include "geometry/triangle.h"

namespace sahara {

/// Four triangles: p[v][axis][lane] is coordinate `axis` of vertex v.
struct alignas(16) TriangleBlock4 {
    float p[3][3][4];  ///< 144 bytes
    /// Each lane's primitive: a triangle's prim id (kind bits zero), kOtherKind | index into the
    /// accelerator's table of other kinds, or kEmptyLane for padding.
    uint32_t slot[4];

    static constexpr uint32_t kOtherKind = 0x80000000u;
    /// Sign bit clear, so the sign-bit mask of `slot` holds exactly the other-kind lanes
    /// (padding lanes have NaN vertices and never hit).
    static constexpr uint32_t kEmptyLane = 0x7FFFFFFFu;
};
static_assert(sizeof(TriangleBlock4) == 160, "40 bytes per triangle, like a leaf slot");

/// Sign bits of a block's slots: its lanes of other kinds (padding has the sign bit clear).
inline int other_lanes(const TriangleBlock4& block) {
    return _mm_movemask_ps(_mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(block.slot))));
}

/// max(|a[0]|, |a[1]|, |a[2]|) per lane: the maxima t_scaled_error_bound takes.
__attribute__((always_inline)) inline __m128 max_abs3(const __m128 a[3]) {
    const __m128 sign = _mm_set1_ps(-0.0f);
    return _mm_max_ps(_mm_max_ps(_mm_andnot_ps(sign, a[0]), _mm_andnot_ps(sign, a[1])),
                      _mm_andnot_ps(sign, a[2]));
}
__attribute__((target("avx2"), always_inline)) inline __m256 max_abs3(const __m256 a[3]) {
    const __m256 sign = _mm256_set1_ps(-0.0f);
    return _mm256_max_ps(_mm256_max_ps(_mm256_andnot_ps(sign, a[0]), _mm256_andnot_ps(sign, a[1])),
                         _mm256_andnot_ps(sign, a[2]));
}

/// Scalar redo of the lanes of `b` in `lanes` (bit l: lane l) that the SIMD step left
/// to it (double fallback included); returns the hit lanes as
/// bits `shift + l`, their answers written to t/u/v_out[shift + l].
template <class TieBreak = EdgesInclusive>
__attribute__((always_inline)) inline int redo_scalar_lanes(const TriangleRay& tr, const TriangleBlock4& b,
                                                            int lanes, int shift, float tmin, float tmax,
                                                            float* t_out, float* u_out, float* v_out) {
    int result = 0;
    for (; lanes; lanes &= lanes - 1) {
        const int l = __builtin_ctz(unsigned(lanes));
        if ((b.slot[l] & TriangleBlock4::kOtherKind) || b.slot[l] == TriangleBlock4::kEmptyLane) continue;
        const TriangleVerts tri{{{b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]},
                                 {b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]},
                                 {b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]}}};
        if (const std::optional<ShapeHit> h = tri.intersect<TieBreak>(tr, tmin, tmax)) {
            t_out[shift + l] = h->t, u_out[shift + l] = h->u, v_out[shift + l] = h->v;
            result |= 1 << (shift + l);
        }
    }
    return result;
}

/// Tests the four lanes of `b` except those with an edge function of exactly 0 or a
/// hit within the rounding of t = 0, which it returns in `scalar_lanes`
/// (intersect_triangle_block4 redoes them; this
/// part calls no function, so it fits the traversal's call-free inner loop).
/// Returns the mask of lanes hit in (tmin, tmax) and their distances and barycentrics.
__attribute__((always_inline)) inline int intersect_triangle_block4_simd(const TriangleRay& tr,
                                                                         const TriangleBlock4& b, float tmin,
                                                                         float tmax, float t_out[4],
                                                                         float u_out[4], float v_out[4],
                                                                         int& scalar_lanes) {
    const int kx = tr.kx, ky = tr.ky, kz = tr.kz;
    const __m128 ox = _mm_set1_ps(tr.org[kx]), oy = _mm_set1_ps(tr.org[ky]), oz = _mm_set1_ps(tr.org[kz]);
    const __m128 sx = _mm_set1_ps(tr.sx), sy = _mm_set1_ps(tr.sy), sz = _mm_set1_ps(tr.sz);
    __m128 x[3], y[3], rz[3];
    for (int v = 0; v < 3; ++v) {
        rz[v] = _mm_sub_ps(_mm_load_ps(b.p[v][kz]), oz);
        x[v] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b.p[v][kx]), ox), _mm_mul_ps(sx, rz[v]));
        y[v] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b.p[v][ky]), oy), _mm_mul_ps(sy, rz[v]));
    }
    // u = cx by - cy bx, v = ax cy - ay cx, w = bx ay - by ax (as in TriangleVerts::intersect).
    const __m128 u = _mm_sub_ps(_mm_mul_ps(x[2], y[1]), _mm_mul_ps(y[2], x[1]));
    const __m128 v = _mm_sub_ps(_mm_mul_ps(x[0], y[2]), _mm_mul_ps(y[0], x[2]));
    const __m128 w = _mm_sub_ps(_mm_mul_ps(x[1], y[0]), _mm_mul_ps(y[1], x[0]));
    const __m128 zero = _mm_setzero_ps();
    // A lane with an edge function of exactly 0 goes to the scalar test below. The
    // product also flags products that underflow to 0, which the scalar test then
    // answers just as exactly; NaN (padding) lanes compare unequal.
    scalar_lanes = _mm_movemask_ps(_mm_cmpeq_ps(_mm_mul_ps(_mm_mul_ps(u, v), w), zero));
    // With no zero among them, u, v, w of a hit share one sign: differing sign bits miss.
    const int mixed = _mm_movemask_ps(_mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(u, w)));
    int mask = ~(mixed | scalar_lanes) & 0xF;
    // No branch on the sign test: whether any lane passes it is a coin toss for the predictor.
    const __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
    const __m128 t_scaled = _mm_mul_ps(
        sz, _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, rz[0]), _mm_mul_ps(v, rz[1])), _mm_mul_ps(w, rz[2])));
    const __m128 sign = _mm_and_ps(det, _mm_set1_ps(-0.0f));
    const __m128 abs_det = _mm_xor_ps(det, sign);
    const __m128 t_signed = _mm_xor_ps(t_scaled, sign);
    // No test of det != 0 (the scalar test's): the lanes left in `mask` have u, v, w
    // non-zero with one sign bit, and such a sum is never 0. NaN lanes fail the ordered
    // comparisons.
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(t_signed, _mm_mul_ps(_mm_set1_ps(tmin), abs_det)),
                                 _mm_cmplt_ps(t_signed, _mm_mul_ps(_mm_set1_ps(tmax), abs_det)));
    mask &= _mm_movemask_ps(ok);
    int result = 0;
    if (mask) {
        const __m128 inv_det = _mm_div_ps(_mm_set1_ps(1.0f), det);
        const __m128 t = _mm_mul_ps(t_scaled, inv_det);
        // Rounding of the division can push t onto the interval's boundary.
        const __m128 in = _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(tmin)), _mm_cmplt_ps(t, _mm_set1_ps(tmax)));
        result = mask & _mm_movemask_ps(in);
        // A triangle wholly ahead of the origin along the dominant axis is hit at t > 0;
        // on one that is not, a t within its rounding bound of 0 is decided by the scalar test.
        const __m128 dz_sign = _mm_and_ps(sz, _mm_set1_ps(-0.0f));
        const __m128 nearest = _mm_min_ps(_mm_min_ps(_mm_xor_ps(rz[0], dz_sign), _mm_xor_ps(rz[1], dz_sign)),
                                          _mm_xor_ps(rz[2], dz_sign));
        if (const int straddling = result & ~_mm_movemask_ps(_mm_cmpgt_ps(nearest, zero))) {
            __m128 bound;
            t_scaled_error_bound(max_abs3(x), max_abs3(y), max_abs3(rz), abs_det, _mm_xor_ps(sz, dz_sign),
                                 bound);
            const int near_zero = straddling & ~_mm_movemask_ps(_mm_cmpgt_ps(t_signed, bound));
            result &= ~near_zero;
            scalar_lanes |= near_zero;
        }
        _mm_storeu_ps(t_out, t);
        _mm_storeu_ps(u_out, _mm_mul_ps(v, inv_det));
        _mm_storeu_ps(v_out, _mm_mul_ps(w, inv_det));
    }
    return result;
}

/// Tests the four lanes of `b`; returns the mask of lanes hit in (tmin, tmax)
/// and their distances and barycentrics.
__attribute__((always_inline)) inline int intersect_triangle_block4(const TriangleRay& tr,
                                                                    const TriangleBlock4& b, float tmin,
                                                                    float tmax, float t_out[4],
                                                                    float u_out[4], float v_out[4]) {
    int scalar_lanes = 0;
    int result = intersect_triangle_block4_simd(tr, b, tmin, tmax, t_out, u_out, v_out, scalar_lanes);
    // Lanes left to the scalar test, double fallback included.
    if (scalar_lanes) result |= redo_scalar_lanes(tr, b, scalar_lanes, 0, tmin, tmax, t_out, u_out, v_out);
    return result;
}

/// Loads lane group [v][axis] of blocks b0 (low half) and b1 (high half).
__attribute__((target("avx2"), always_inline)) inline __m256 load_block_pair(const TriangleBlock4* b0,
                                                                             const TriangleBlock4* b1, int v,
                                                                             int axis) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(b0->p[v][axis])),
                                _mm_load_ps(b1->p[v][axis]), 1);
}

/// intersect_triangle_block4_simd over two blocks in one AVX step (b0 and b1 need
/// not be adjacent: a leaf's two blocks, or two one-block leaves): bit l of the
/// result (and of `scalar_lanes`) is lane l & 3 of b0 for l < 4, of b1 otherwise;
/// t/u/v_out hold 8 lanes. Not always_inline, like WideRay<8, true>::test
/// (traverse_wide.h): it is inlined once its generic caller sits inside the AVX2 traversal.
__attribute__((target("avx2"))) inline int intersect_triangle_blocks2_avx_simd(
    const TriangleRay& tr, const TriangleBlock4* b0, const TriangleBlock4* b1, float tmin, float tmax,
    float t_out[8], float u_out[8], float v_out[8], int& scalar_lanes) {
    const int kx = tr.kx, ky = tr.ky, kz = tr.kz;
    const __m256 ox = _mm256_set1_ps(tr.org[kx]), oy = _mm256_set1_ps(tr.org[ky]),
                 oz = _mm256_set1_ps(tr.org[kz]);
    const __m256 sx = _mm256_set1_ps(tr.sx), sy = _mm256_set1_ps(tr.sy), sz = _mm256_set1_ps(tr.sz);
    __m256 x[3], y[3], rz[3];
    for (int v = 0; v < 3; ++v) {
        rz[v] = _mm256_sub_ps(load_block_pair(b0, b1, v, kz), oz);
        x[v] = _mm256_sub_ps(_mm256_sub_ps(load_block_pair(b0, b1, v, kx), ox), _mm256_mul_ps(sx, rz[v]));
        y[v] = _mm256_sub_ps(_mm256_sub_ps(load_block_pair(b0, b1, v, ky), oy), _mm256_mul_ps(sy, rz[v]));
    }
    const __m256 u = _mm256_sub_ps(_mm256_mul_ps(x[2], y[1]), _mm256_mul_ps(y[2], x[1]));
    const __m256 v = _mm256_sub_ps(_mm256_mul_ps(x[0], y[2]), _mm256_mul_ps(y[0], x[2]));
    const __m256 w = _mm256_sub_ps(_mm256_mul_ps(x[1], y[0]), _mm256_mul_ps(y[1], x[0]));
    const __m256 zero = _mm256_setzero_ps();
    scalar_lanes = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_mul_ps(_mm256_mul_ps(u, v), w), zero, _CMP_EQ_OQ));
    const int mixed = _mm256_movemask_ps(_mm256_or_ps(_mm256_xor_ps(u, v), _mm256_xor_ps(u, w)));
    int mask = ~(mixed | scalar_lanes) & 0xFF;
    const __m256 det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    const __m256 t_scaled =
        _mm256_mul_ps(sz, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, rz[0]), _mm256_mul_ps(v, rz[1])),
                                        _mm256_mul_ps(w, rz[2])));
    const __m256 sign = _mm256_and_ps(det, _mm256_set1_ps(-0.0f));
    const __m256 abs_det = _mm256_xor_ps(det, sign);
    const __m256 t_signed = _mm256_xor_ps(t_scaled, sign);
    const __m256 ok =
        _mm256_and_ps(_mm256_cmp_ps(t_signed, _mm256_mul_ps(_mm256_set1_ps(tmin), abs_det), _CMP_GT_OQ),
                      _mm256_cmp_ps(t_signed, _mm256_mul_ps(_mm256_set1_ps(tmax), abs_det), _CMP_LT_OQ));
    mask &= _mm256_movemask_ps(ok);
    int result = 0;
    if (mask) {
        const __m256 inv_det = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
        const __m256 t = _mm256_mul_ps(t_scaled, inv_det);
        const __m256 in = _mm256_and_ps(_mm256_cmp_ps(t, _mm256_set1_ps(tmin), _CMP_GT_OQ),
                                        _mm256_cmp_ps(t, _mm256_set1_ps(tmax), _CMP_LT_OQ));
        result = mask & _mm256_movemask_ps(in);
        const __m256 dz_sign = _mm256_and_ps(sz, _mm256_set1_ps(-0.0f));
        const __m256 nearest =
            _mm256_min_ps(_mm256_min_ps(_mm256_xor_ps(rz[0], dz_sign), _mm256_xor_ps(rz[1], dz_sign)),
                          _mm256_xor_ps(rz[2], dz_sign));
        if (const int straddling = result & ~_mm256_movemask_ps(_mm256_cmp_ps(nearest, zero, _CMP_GT_OQ))) {
            __m256 bound;
            t_scaled_error_bound(max_abs3(x), max_abs3(y), max_abs3(rz), abs_det, _mm256_xor_ps(sz, dz_sign),
                                 bound);
            const int near_zero =
                straddling & ~_mm256_movemask_ps(_mm256_cmp_ps(t_signed, bound, _CMP_GT_OQ));
            result &= ~near_zero;
            scalar_lanes |= near_zero;
        }
        _mm256_storeu_ps(t_out, t);
        _mm256_storeu_ps(u_out, _mm256_mul_ps(v, inv_det));
        _mm256_storeu_ps(v_out, _mm256_mul_ps(w, inv_det));
    }
    return result;
}

/// intersect_triangle_block4 over the two blocks b[0], b[1] in one AVX step (lanes as
/// in intersect_triangle_blocks2_avx_simd), the lanes it leaves redone by the scalar test.
/// Out of line: the traversal calls it only for leaves its call-free step cannot answer,
/// and inlined there it would crowd the hot loop.
__attribute__((target("avx2"), noinline)) inline int intersect_triangle_blocks2_avx(
    const TriangleRay& tr, const TriangleBlock4* b, float tmin, float tmax, float t_out[8], float u_out[8],
    float v_out[8]) {
    int scalar_lanes = 0;
    int result =
        intersect_triangle_blocks2_avx_simd(tr, b, b + 1, tmin, tmax, t_out, u_out, v_out, scalar_lanes);
    if (scalar_lanes) {
        result |= redo_scalar_lanes(tr, b[0], scalar_lanes & 0xF, 0, tmin, tmax, t_out, u_out, v_out);
        result |= redo_scalar_lanes(tr, b[1], scalar_lanes >> 4, 4, tmin, tmax, t_out, u_out, v_out);
    }
    return result;
}

}  // namespace sahara
