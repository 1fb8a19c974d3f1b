#pragma once
/// The ray-box tests of a wide node: per-ray constants and one step that tests all
/// children of a node, in SSE2 (an 8-wide node as two halves), AVX2 and AVX-512.
/// Robustness is that of bvh_traverse.h: NaN from 0 * inf (origin on a slab plane,
/// zero direction component) is ignored, and the far distance is enlarged by
/// 1 + 2 gamma(3) (Ize, "Robust BVH Ray Traversal", 2013). Unused child slots hold an
/// empty box (lo = +inf, hi = -inf), which no ray with a finite origin can hit.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <immintrin.h>

#include "accel/bvh_traverse.h"
#include "accel/bvh_wide.h"

namespace sahara {

/// Per-ray constants of the SSE box test of an N-wide node: broadcast origin and
/// inverse direction, and the byte offsets of each axis's near and far planes in a node.
template <int N>
struct WideRaySse {
    __m128 org[3], inv[3], inv_far[3];
    uint32_t near_off[3], far_off[3];

    explicit WideRaySse(const BvhRay& r) {
        using Node = BvhWideNode<N>;
        const uint32_t lo[3] = {offsetof(Node, lo_x), offsetof(Node, lo_y), offsetof(Node, lo_z)};
        const uint32_t hi[3] = {offsetof(Node, hi_x), offsetof(Node, hi_y), offsetof(Node, hi_z)};
        for (int a = 0; a < 3; ++a) {
            org[a] = _mm_set1_ps(r.org[a]);
            inv[a] = _mm_set1_ps(r.inv_dir[a]);
            inv_far[a] = _mm_set1_ps(r.inv_far[a]);
            // Near plane of an axis is `hi` for a negative direction.
            near_off[a] = r.neg[a] ? hi[a] : lo[a];
            far_off[a] = r.neg[a] ? lo[a] : hi[a];
        }
    }
};

/// Tests children [4 g, 4 g + 4) of an N-wide node with SSE; bit c of the result
/// is set when child 4 g + c is hit, and lane c of t_near is then its entry
/// distance. Same answers as intersect_bvh_node per child.
template <int N>
__attribute__((always_inline)) inline int intersect_wide_sse(const BvhWideNode<N>& n, const WideRaySse<N>& r,
                                                             int g, float tmin, float tmax_far,
                                                             __m128& t_near) {
    // The order of intersect_bvh_node: _mm_max_ps(x, acc) and _mm_min_ps(x, acc)
    // return acc when x is NaN.
    const char* base = reinterpret_cast<const char*>(&n) + 16 * g;
    __m128 tn[3], tf[3];
    for (int a = 0; a < 3; ++a) {
        const __m128 near = _mm_load_ps(reinterpret_cast<const float*>(base + r.near_off[a]));
        const __m128 far = _mm_load_ps(reinterpret_cast<const float*>(base + r.far_off[a]));
        tn[a] = _mm_mul_ps(_mm_sub_ps(near, r.org[a]), r.inv[a]);
        tf[a] = _mm_mul_ps(_mm_sub_ps(far, r.org[a]), r.inv_far[a]);
    }
    const __m128 t0 = _mm_max_ps(_mm_max_ps(tn[1], tn[2]), _mm_max_ps(tn[0], _mm_set1_ps(tmin)));
    const __m128 t1 = _mm_min_ps(_mm_min_ps(tf[1], tf[2]), _mm_min_ps(tf[0], _mm_set1_ps(tmax_far)));
    t_near = t0;
    return _mm_movemask_ps(_mm_cmple_ps(t0, t1));
}

/// Per-ray constants of the AVX box test of an 8-wide node: broadcast origin, negated
/// inverse direction for the near planes and inverse direction for the far planes (see
/// BvhRay), and the byte offsets of each axis's near and far planes.
/// The near planes' test computes (org - plane) * -inv, which rounds exactly like
/// (plane - org) * inv (round-to-nearest is symmetric under negation) but lets the plane
/// be a memory operand of the subtraction; the far planes' (org - plane) * inv_far is the
/// negated exit distance that bvh8_distances_avx reduces.
struct Bvh8RayAvx {
    __m256 org[3], ninv[3], inv_far[3];
    /// Pointer-sized, so that the addressing needs no extension of them at every node.
    size_t near_off[3], far_off[3];

    Bvh8RayAvx() = default;
    /// Not always_inline, like WideRay<8, true>::test below: it is inlined once its
    /// generic caller sits inside an AVX2 function.
    __attribute__((target("avx2"))) explicit Bvh8RayAvx(const BvhRay& r) {
        // lo_x, hi_x, lo_y, ... are consecutive 32-byte arrays: an axis's planes start at
        // 64 a; the near plane is `hi` (32 bytes further) for a negative direction.
        static_assert(offsetof(Bvh8Node, hi_x) == 32 && offsetof(Bvh8Node, lo_y) == 64);
        for (int a = 0; a < 3; ++a) {
            org[a] = _mm256_set1_ps(r.org[a]);
            ninv[a] = _mm256_set1_ps(-r.inv_dir[a]);
            inv_far[a] = _mm256_set1_ps(r.inv_far[a]);
            near_off[a] = size_t(64 * a + 32 * r.neg[a]);
            far_off[a] = near_off[a] ^ 32;
        }
    }
};

/// The slab distances of an 8-wide node's children in one AVX step, reduced as
/// integers: one cycle where a float max or min takes four, on the chain every node
/// step waits for. That needs tmin >= 0:
///  - entry: the signed-integer max of the near distances and tmin. Non-negative
///    floats order like their bit patterns, and every negative float, the NaN of
///    0 * inf (sign bit set on x86: a ray in a slab plane) included, is a negative
///    integer and loses to tmin, so that axis is dropped as it should be;
///  - neg_exit: the far distances are computed negated, (org - far) * inv_far = -t1
///    exactly, and reduced with -tmax_far by an unsigned min. Negative floats (exits
///    ahead) order by magnitude as unsigned integers; the NaN (0xFFC00000) is above
///    them all and loses; a non-negative one (an exit behind the origin) is below them
///    all and wins, and the child is then missed.
/// A child is hit when neg_exit - 1 >= entry + 0x7FFFFFFF (unsigned), i.e. |exit| >=
/// entry for a negative exit. A negated exit of +0 (the origin exactly on the far plane
/// of a positive direction) wraps to all ones and counts as a hit: never a miss the
/// exact slab test would hit. Each NaN is dropped on its own, so the hits can be fewer
/// than those of intersect_bvh_node and the SSE test, which drop a whole pair of
/// distances around a NaN; both are conservative.
__attribute__((target("avx2"), always_inline)) inline void bvh8_distances_avx(const Bvh8Node& n,
                                                                              const Bvh8RayAvx& r, float tmin,
                                                                              float tmax_far, __m256i& entry,
                                                                              __m256i& neg_exit) {
    const char* base = reinterpret_cast<const char*>(&n);
    __m256i tn[3], ntf[3];
    for (int a = 0; a < 3; ++a) {
        const __m256 near = _mm256_load_ps(reinterpret_cast<const float*>(base + r.near_off[a]));
        const __m256 far = _mm256_load_ps(reinterpret_cast<const float*>(base + r.far_off[a]));
        tn[a] = _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(r.org[a], near), r.ninv[a]));
        ntf[a] = _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(r.org[a], far), r.inv_far[a]));
    }
    // max with 0: a tmin of -0 would be the smallest integer, not 0.
    const __m256i lo = _mm256_max_epi32(_mm256_castps_si256(_mm256_set1_ps(tmin)), _mm256_setzero_si256());
    entry = _mm256_max_epi32(_mm256_max_epi32(tn[1], tn[2]), _mm256_max_epi32(tn[0], lo));
    neg_exit = _mm256_min_epu32(_mm256_min_epu32(ntf[1], ntf[2]),
                                _mm256_min_epu32(ntf[0], _mm256_castps_si256(_mm256_set1_ps(-tmax_far))));
}

/// The eight children of a BVH8 node in one AVX2 step (bvh8_distances_avx): mask of the
/// hit children, entry distances to t_near[0..8). AVX2 has no unsigned compare, so the
/// hit test flips the sign bits of both sides: neg_exit - 1 >=u entry + 0x7FFFFFFF is
/// neg_exit + 0x7FFFFFFF >=s entry - 1.
__attribute__((target("avx2"), always_inline)) inline int intersect_bvh8_avx(const Bvh8Node& n,
                                                                             const Bvh8RayAvx& r, float tmin,
                                                                             float tmax_far, float* t_near) {
    __m256i entry, neg_exit;
    bvh8_distances_avx(n, r, tmin, tmax_far, entry, neg_exit);
    _mm256_store_si256(reinterpret_cast<__m256i*>(t_near), entry);
    const __m256i miss = _mm256_cmpgt_epi32(_mm256_add_epi32(entry, _mm256_set1_epi32(-1)),
                                            _mm256_add_epi32(neg_exit, _mm256_set1_epi32(0x7FFFFFFF)));
    return ~_mm256_movemask_ps(_mm256_castsi256_ps(miss)) & 0xFF;
}

/// What an AVX-512 node step found: the hit mask (or, for a pair of nodes, the number of
/// hit children) and the first hit child (lowest slot) with its entry distance.
struct Bvh8HitChildren {
    unsigned mask;
    uint32_t ref0;
    float t0;
};

/// The box test of the AVX-512 node steps (bvh8_distances_avx, then one unsigned
/// compare into a mask register): mask of the hit children, their entry distances (as
/// bit patterns) in `entry`.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline __mmask8 bvh8_hits_avx512(
    const Bvh8Node& n, const Bvh8RayAvx& r, float tmin, float tmax_far, __m256i& entry) {
    __m256i neg_exit;
    bvh8_distances_avx(n, r, tmin, tmax_far, entry, neg_exit);
    const __m256i a = _mm256_add_epi32(entry, _mm256_set1_epi32(0x7FFFFFFF));
    const __m256i b = _mm256_sub_epi32(neg_exit, _mm256_set1_epi32(1));
    // _mm256_cmp_epu32_mask(a, b, _MM_CMPINT_LE), written out so that the mask lands in
    // k1-k7 ("Yk"), which can predicate the compressions: GCC picks k0 and then needs a
    // kmov on the node step's dependency chain.
    __mmask8 k;
    asm("vpcmpud $2, %[b], %[a], %[k]" : [k] "=Yk"(k) : [a] "v"(a), [b] "v"(b));
    return k;
}

/// The words v[0..8) of the lanes in k, moved to the front (zeros after them).
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"), always_inline)) inline __m256i
compress_words(__mmask8 k, const uint32_t* v) {
    return _mm256_maskz_compress_epi32(k, _mm256_load_si256(reinterpret_cast<const __m256i*>(v)));
}

/// Writes eight stack entries (see traverse_wide) to out[0..8): lane i of `ref` in the low
/// word of entry i, lane i of `t` in its high word.
__attribute__((target("avx2"), always_inline)) inline void store_stack_entries(uint64_t* out, __m256i ref,
                                                                               __m256i t) {
    const __m256i lo = _mm256_unpacklo_epi32(ref, t);  // entries 0, 1 | 4, 5
    const __m256i hi = _mm256_unpackhi_epi32(ref, t);  // entries 2, 3 | 6, 7
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_permute2x128_si256(lo, hi, 0x20));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 4), _mm256_permute2x128_si256(lo, hi, 0x31));
}

/// The AVX-512 node step of a closest-hit ray: the hit children's references and entry
/// distances compressed to the front of ref/t[0..8) (slot order, zeros after them). The
/// first hit child also comes back in registers, so the next node's address waits for
/// neither a bit scan nor a load.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline Bvh8HitChildren
intersect_bvh8_compress_avx512(const Bvh8Node& n, const Bvh8RayAvx& r, float tmin, float tmax_far,
                               uint32_t* ref, float* t) {
    __m256i entry;
    const __mmask8 k = bvh8_hits_avx512(n, r, tmin, tmax_far, entry);
    const __m256i ch = compress_words(k, n.child);
    const __m256 tc = _mm256_maskz_compress_ps(k, _mm256_castsi256_ps(entry));
    _mm256_store_si256(reinterpret_cast<__m256i*>(ref), ch);
    _mm256_store_ps(t, tc);
    return {unsigned(k), uint32_t(_mm256_cvtsi256_si32(ch)), _mm256_cvtss_f32(tc)};
}

/// The AVX-512 node step of a closest-hit ray over two nodes: `a`, the node visited now,
/// and `b`, the inner node on top of the stack. The stack entries of the hit children of
/// a, then those of b (slot order), are compressed to entries[0..16); `mask` of the result
/// is their number, and the first of them also comes back in registers. The two box tests
/// depend on nothing of each other, so the out-of-order core overlaps them, where visiting
/// b later would wait for a chain of its own.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline Bvh8HitChildren
intersect_bvh8_pair_avx512(const Bvh8Node& a, const Bvh8Node& b, const Bvh8RayAvx& r, float tmin,
                           float tmax_far, uint64_t* entries) {
    __m256i entry_a, entry_b;
    const __mmask8 ka = bvh8_hits_avx512(a, r, tmin, tmax_far, entry_a);
    const __mmask8 kb = bvh8_hits_avx512(b, r, tmin, tmax_far, entry_b);
    const __m256i ca = compress_words(ka, a.child), cb = compress_words(kb, b.child);
    const __m256i ta = _mm256_maskz_compress_epi32(ka, entry_a);
    const __m256i tb = _mm256_maskz_compress_epi32(kb, entry_b);
    const int hits_a = __builtin_popcount(unsigned(ka));
    store_stack_entries(entries, ca, ta);
    store_stack_entries(entries + hits_a, cb, tb);
    const bool from_a = ka != 0;
    return {unsigned(hits_a + __builtin_popcount(unsigned(kb))),
            uint32_t(_mm256_cvtsi256_si32(from_a ? ca : cb)),
            std::bit_cast<float>(uint32_t(_mm256_cvtsi256_si32(from_a ? ta : tb)))};
}

/// The AVX-512 node step of an any-hit ray: the first hit child (lowest slot) comes back
/// in registers, the other hit children as stack entries (reference; any hit needs no
/// distance) in slot order, all eight entries written to entries[0..8) (those past the
/// hits are garbage), so that pushing them takes no loop over the hits, and the next
/// node's address waits for neither the stack nor a bit count. Visiting the first hit child
/// first, not the last (Embree's order, read back from the stack), wins on most meshes here;
/// the order alone, without the shorter chain, wins on some meshes and loses on others, so
/// the AVX2 step keeps Embree's.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline Bvh8HitChildren
intersect_bvh8_entries_avx512(const Bvh8Node& n, const Bvh8RayAvx& r, float tmin, float tmax_far,
                              uint64_t* entries) {
    __m256i entry;
    const __mmask8 k = bvh8_hits_avx512(n, r, tmin, tmax_far, entry);
    const __m256i ch = compress_words(k, n.child);
    // From the second hit on, each reference in the low word of an entry (the high word,
    // the distance, is garbage: an any-hit ray reads none).
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(entries),
                        _mm256_permutexvar_epi32(_mm256_setr_epi32(1, 1, 2, 2, 3, 3, 4, 4), ch));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(entries + 4),
                        _mm256_permutexvar_epi32(_mm256_setr_epi32(5, 5, 6, 6, 7, 7, 7, 7), ch));
    return {unsigned(k), uint32_t(_mm256_cvtsi256_si32(ch)), 0.0f};
}

/// Box constants of one ray for an N-wide node: AVX for an 8-wide node when
/// kAvx (the caller is compiled for AVX2), SSE otherwise.
template <int N, bool kAvx>
struct WideRay;
template <int N>
struct WideRay<N, false> {
    WideRaySse<N> sse;
    explicit WideRay(const BvhRay& r) : sse(r) {}
    /// Tests all N children against (tmin, tmax_far = tmax * kRobustFarScale): mask of
    /// hit children, entry distances in t[0..N).
    __attribute__((always_inline)) int test(const BvhWideNode<N>& n, float tmin, float tmax_far,
                                            float* t) const {
        int mask = 0;
        for (int g = 0; g < N / 4; ++g) {
            __m128 tv;
            mask |= intersect_wide_sse<N>(n, sse, g, tmin, tmax_far, tv) << (4 * g);
            _mm_store_ps(t + 4 * g, tv);
        }
        return mask;
    }
};
template <>
struct WideRay<8, true> {
    Bvh8RayAvx avx;
    __attribute__((always_inline)) explicit WideRay(const BvhRay& r) : avx(r) {}
    /// Not always_inline: GCC inlines callees into traverse_wide before traverse_wide
    /// itself is inlined into its AVX2 caller, and refuses AVX2 code in that generic
    /// body; as a plain inline function it is inlined once it sits in the AVX2 caller.
    __attribute__((target("avx2"))) int test(const Bvh8Node& n, float tmin, float tmax_far, float* t) const {
        return intersect_bvh8_avx(n, avx, tmin, tmax_far, t);
    }
};

}  // namespace sahara
