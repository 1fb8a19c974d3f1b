#pragma once
/// BVH4 leaves as blocks of four triangles in structure-of-arrays form, tested
/// with SSE four at a time by the watertight test of Woop, Benthin and Wald
/// ("Watertight Ray/Triangle Intersection", JCGT 2013). Every lane performs
/// exactly the float operations of intersect_triangle (geometry/triangle.h),
/// in the same order and without fused multiply-adds, so the answers are
/// bit-identical; a lane whose edge function is exactly 0 is redone by the
/// scalar test (which then falls back to double, as the paper requires).
///
/// Lanes that hold no triangle (another primitive kind, or padding) have NaN
/// vertices, which every comparison rejects; the caller tests those kinds itself.
#include <cstdint>

#include <emmintrin.h>

#include "geometry/triangle.h"

namespace sahara {

/// Four triangles: p[v][axis][lane] is coordinate `axis` of vertex v.
struct alignas(16) TriangleBlock4 {
    float p[3][3][4];  ///< 144 bytes
    /// Leaf slot of each lane; kOtherKind set for a non-triangle slot, kEmptyLane for padding.
    uint32_t slot[4];

    static constexpr uint32_t kOtherKind = 0x80000000u;
    static constexpr uint32_t kEmptyLane = 0xFFFFFFFFu;
};
static_assert(sizeof(TriangleBlock4) == 160, "40 bytes per triangle, like a leaf slot");

/// Tests the four lanes of `b`; returns the mask of lanes hit in (tmin, tmax)
/// and their distances and barycentrics.
__attribute__((always_inline)) inline int intersect_triangle_block4(const TriangleRay& tr,
                                                                    const TriangleBlock4& b, float tmin,
                                                                    float tmax, float t_out[4],
                                                                    float u_out[4], float v_out[4]) {
    const int kx = tr.kx, ky = tr.ky, kz = tr.kz;
    const __m128 ox = _mm_set1_ps(tr.org[kx]), oy = _mm_set1_ps(tr.org[ky]), oz = _mm_set1_ps(tr.org[kz]);
    const __m128 sx = _mm_set1_ps(tr.sx), sy = _mm_set1_ps(tr.sy), sz = _mm_set1_ps(tr.sz);
    __m128 x[3], y[3], z[3];
    for (int v = 0; v < 3; ++v) {
        const __m128 rz = _mm_sub_ps(_mm_load_ps(b.p[v][kz]), oz);
        x[v] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b.p[v][kx]), ox), _mm_mul_ps(sx, rz));
        y[v] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b.p[v][ky]), oy), _mm_mul_ps(sy, rz));
        z[v] = _mm_mul_ps(sz, rz);
    }
    // u = cx by - cy bx, v = ax cy - ay cx, w = bx ay - by ax (as in intersect_triangle).
    const __m128 u = _mm_sub_ps(_mm_mul_ps(x[2], y[1]), _mm_mul_ps(y[2], x[1]));
    const __m128 v = _mm_sub_ps(_mm_mul_ps(x[0], y[2]), _mm_mul_ps(y[0], x[2]));
    const __m128 w = _mm_sub_ps(_mm_mul_ps(x[1], y[0]), _mm_mul_ps(y[1], x[0]));
    const __m128 zero = _mm_setzero_ps();
    const int exact_zero = _mm_movemask_ps(
        _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero)));
    const __m128 any_neg =
        _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
    const __m128 any_pos =
        _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
    const __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
    const __m128 t_scaled =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, z[0]), _mm_mul_ps(v, z[1])), _mm_mul_ps(w, z[2]));
    const __m128 sign = _mm_and_ps(det, _mm_set1_ps(-0.0f));
    const __m128 abs_det = _mm_xor_ps(det, sign);
    const __m128 t_signed = _mm_xor_ps(t_scaled, sign);
    __m128 ok = _mm_andnot_ps(_mm_and_ps(any_neg, any_pos), _mm_cmpneq_ps(det, zero));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(t_signed, _mm_mul_ps(_mm_set1_ps(tmin), abs_det)));
    ok = _mm_and_ps(ok, _mm_cmplt_ps(t_signed, _mm_mul_ps(_mm_set1_ps(tmax), abs_det)));
    int mask = _mm_movemask_ps(ok) & ~exact_zero;
    int result = 0;
    if (mask) {
        const __m128 inv_det = _mm_div_ps(_mm_set1_ps(1.0f), det);
        const __m128 t = _mm_mul_ps(t_scaled, inv_det);
        // Rounding of the division can push t onto the interval's boundary.
        const __m128 in = _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(tmin)), _mm_cmplt_ps(t, _mm_set1_ps(tmax)));
        result = mask & _mm_movemask_ps(in);
        _mm_storeu_ps(t_out, t);
        _mm_storeu_ps(u_out, _mm_mul_ps(v, inv_det));
        _mm_storeu_ps(v_out, _mm_mul_ps(w, inv_det));
    }
    // Lanes with an exactly-zero edge function: the scalar test, double fallback included.
    for (int lanes = exact_zero; lanes; lanes &= lanes - 1) {
        const int l = __builtin_ctz(unsigned(lanes));
        if (b.slot[l] & TriangleBlock4::kOtherKind) continue;
        const TriangleVerts tri{{{b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]},
                                 {b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]},
                                 {b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]}}};
        TriangleHit h{};
        if (intersect_triangle(tr, tri, tmin, tmax, h)) {
            t_out[l] = h.t, u_out[l] = h.u, v_out[l] = h.v;
            result |= 1 << l;
        }
    }
    return result;
}

}  // namespace sahara
