#include "accel/ray_stream.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>

#include "accel/simd_path.h"

namespace sahara {

void RayStream::add(const BvhRay& r) {
    const int i = size++;
    for (int a = 0; a < 3; ++a) {
        org[a][i] = r.org[a];
        ninv[a][i] = -r.inv_dir[a];
        inv_far[a][i] = r.inv_far[a];
    }
    // As Bvh8RayAvx and bvh8_distances_avx make them.
    tmin_bits[i] = std::max(std::bit_cast<int32_t>(r.tmin), 0);
    neg_tmax_far[i] = std::bit_cast<int32_t>(-(r.tmax * kRobustFarScale));
    neg_axes[i] = r.neg[0] | r.neg[1] << 1 | r.neg[2] << 2;
    frontier_count[i] = 0;
    overflow[i] = false;
}

namespace {

/// A node waiting in the stream with the ids of the rays that reached it.
struct StreamEntry {
    uint32_t ref;
    int depth;
    int first, count;  ///< its ids in the arena
    int arena_end;     ///< the end of its siblings' lists: the arena's top once it is popped
};

/// Rays per group: one AVX-512 step, two AVX2 steps.
constexpr int kGroupRays = 16;
constexpr int kGroups = kMaxStreamRays / kGroupRays;
/// Each level's lists hold at most eight ids per ray (one per child).
constexpr int kArenaIds = 8 * kMaxStreamRays * (kMaxStreamDepth + 1);
constexpr int kStackEntries = 8 * (kMaxStreamDepth + 1);

/// The scratch of one walk: lists of ray ids, the nodes waiting, one node's hit masks and
/// entry distances per group of rays.
struct StreamScratch {
    alignas(64) uint32_t ids[kArenaIds + kGroupRays];
    StreamEntry stack[kStackEntries];
    uint16_t mask[kGroups][8];
    alignas(64) int32_t entry[kGroups][8][kGroupRays];
};

/// Permutations that move the lanes of an 8-bit mask to the front (AVX2 has no compress).
struct CompressTable {
    alignas(32) uint32_t lanes[256][8];
    constexpr CompressTable() : lanes() {
        for (int m = 0; m < 256; ++m) {
            int k = 0;
            for (int i = 0; i < 8; ++i)
                if (m >> i & 1) lanes[m][k++] = uint32_t(i);
        }
    }
};
constexpr CompressTable kCompress;

// The helpers below carry their instruction set: GCC refuses intrinsics in the generic
// walk(), and inlines them once walk() sits in walk_avx2 or walk_avx512.

/// Appends the ids[0..16) of the lanes in m to `out` (up to 16 words past it written).
__attribute__((target("avx2"))) inline void append_ids_avx2(uint32_t* out, const uint32_t* ids, unsigned m) {
    for (int h = 0; h < 2; ++h) {
        const unsigned mh = m >> (8 * h) & 0xFF;
        const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + 8 * h));
        const __m256i perm = _mm256_load_si256(reinterpret_cast<const __m256i*>(kCompress.lanes[mh]));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_permutevar8x32_epi32(v, perm));
        out += std::popcount(mh);
    }
}

__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline void append_ids_avx512(
    uint32_t* out, const uint32_t* ids, unsigned m) {
    _mm512_mask_compressstoreu_epi32(out, __mmask16(m), _mm512_loadu_si512(ids));
}

/// Adds child `ref` with its entry distances entry[0..16) to the frontiers of the rays
/// ids[0..16) in lanes m (each ray once: no two lanes write the same place).
inline void append_frontier(RayStream& s, const uint32_t* ids, unsigned m, const int32_t* entry,
                            uint32_t ref) {
    for (; m; m &= m - 1) {
        const int l = std::countr_zero(m);
        const uint32_t r = ids[l];
        const int k = s.frontier_count[r];
        if (k == kStreamFrontierCap) {
            s.overflow[r] = true;
            continue;
        }
        s.frontier[r][k] = uint64_t(uint32_t(entry[l])) << 32 | ref;
        s.frontier_count[r] = k + 1;
    }
}

// GCC 12 reports its own AVX-512 headers' _mm512_undefined_* sources as maybe
// uninitialised once these functions are inlined.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

/// append_frontier with scatters: no branch per ray.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline void append_frontier_avx512(
    RayStream& s, const uint32_t* ids, unsigned m, const int32_t* entry, uint32_t ref) {
    const auto lanes = __mmask16(m);
    const __m512i id = _mm512_maskz_loadu_epi32(lanes, ids);
    const __m512i k = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), lanes, id, s.frontier_count, 4);
    const __mmask16 full = _mm512_mask_cmpge_epi32_mask(lanes, k, _mm512_set1_epi32(kStreamFrontierCap));
    for (unsigned f = full; f; f &= f - 1) s.overflow[ids[std::countr_zero(f)]] = true;
    const __mmask16 put = lanes & __mmask16(~full);
    const __m512i slot = _mm512_add_epi32(_mm512_mullo_epi32(id, _mm512_set1_epi32(kStreamFrontierCap)), k);
    const __m512i t = _mm512_loadu_si512(entry);
    const __m512i r64 = _mm512_set1_epi64(int64_t(ref));
    const __m512i lo =
        _mm512_or_si512(_mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_castsi512_si256(t)), 32), r64);
    const __m512i hi =
        _mm512_or_si512(_mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(t, 1)), 32), r64);
    _mm512_mask_i32scatter_epi64(&s.frontier[0][0], __mmask8(put), _mm512_castsi512_si256(slot), lo, 8);
    _mm512_mask_i32scatter_epi64(&s.frontier[0][0], __mmask8(put >> 8), _mm512_extracti64x4_epi64(slot, 1),
                                 hi, 8);
    _mm512_mask_i32scatter_epi32(s.frontier_count, put, id, _mm512_add_epi32(k, _mm512_set1_epi32(1)), 4);
}

#pragma GCC diagnostic pop

/// Tests the rays ids[0..count) against the children of node `n` eight at a time: masks
/// and entry distances per group into `sc`.
__attribute__((target("avx2"))) inline void test_children_avx2(const Bvh8Node& n, int children,
                                                               const RayStream& s, const uint32_t* ids,
                                                               int count, StreamScratch& sc) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const float* lo_planes[3] = {n.lo_x, n.lo_y, n.lo_z};
    const float* hi_planes[3] = {n.hi_x, n.hi_y, n.hi_z};
    for (int h = 0; 8 * h < count; ++h) {
        const int g = h / 2, half = h % 2;
        const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(count - 8 * h), lane);
        // Lanes past the list's end read ray 0 and are masked off.
        const __m256i id =
            _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + 8 * h)), valid);
        __m256 org[3], ninv[3], inv_far[3];
        __m256i neg[3];
        const __m256i axes = _mm256_i32gather_epi32(s.neg_axes, id, 4);
        for (int a = 0; a < 3; ++a) {
            org[a] = _mm256_i32gather_ps(s.org[a], id, 4);
            ninv[a] = _mm256_i32gather_ps(s.ninv[a], id, 4);
            inv_far[a] = _mm256_i32gather_ps(s.inv_far[a], id, 4);
            neg[a] = _mm256_slli_epi32(axes, 31 - a);  // sign bit: the near plane is hi
        }
        const __m256i lo = _mm256_i32gather_epi32(s.tmin_bits, id, 4);
        const __m256i ntmax = _mm256_i32gather_epi32(s.neg_tmax_far, id, 4);
        const unsigned valid_bits = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(valid)));
        for (int c = 0; c < children; ++c) {
            __m256i tn[3], ntf[3];
            for (int a = 0; a < 3; ++a) {
                const __m256 l = _mm256_set1_ps(lo_planes[a][c]), hp = _mm256_set1_ps(hi_planes[a][c]);
                const __m256 sel = _mm256_castsi256_ps(neg[a]);
                const __m256 near = _mm256_blendv_ps(l, hp, sel), far = _mm256_blendv_ps(hp, l, sel);
                // bvh8_distances_avx's operations, ray per lane instead of child per lane.
                tn[a] = _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(org[a], near), ninv[a]));
                ntf[a] = _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(org[a], far), inv_far[a]));
            }
            const __m256i entry =
                _mm256_max_epi32(_mm256_max_epi32(tn[1], tn[2]), _mm256_max_epi32(tn[0], lo));
            const __m256i neg_exit =
                _mm256_min_epu32(_mm256_min_epu32(ntf[1], ntf[2]), _mm256_min_epu32(ntf[0], ntmax));
            const __m256i miss =
                _mm256_cmpgt_epi32(_mm256_add_epi32(entry, _mm256_set1_epi32(-1)),
                                   _mm256_add_epi32(neg_exit, _mm256_set1_epi32(0x7FFFFFFF)));
            const unsigned m = ~unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(miss))) & valid_bits;
            sc.mask[g][c] = uint16_t(half ? (sc.mask[g][c] | m << 8) : m);
            _mm256_store_si256(reinterpret_cast<__m256i*>(sc.entry[g][c] + 8 * half), entry);
        }
    }
}

/// test_children_avx2 sixteen rays at a time.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) inline void test_children_avx512(
    const Bvh8Node& n, int children, const RayStream& s, const uint32_t* ids, int count, StreamScratch& sc) {
    const float* lo_planes[3] = {n.lo_x, n.lo_y, n.lo_z};
    const float* hi_planes[3] = {n.hi_x, n.hi_y, n.hi_z};
    for (int g = 0; kGroupRays * g < count; ++g) {
        const int left = count - kGroupRays * g;
        const auto valid = __mmask16(left >= kGroupRays ? 0xFFFF : (1u << left) - 1);
        const __m512i id = _mm512_maskz_loadu_epi32(valid, ids + kGroupRays * g);
        __m512 org[3], ninv[3], inv_far[3];
        __mmask16 neg[3];
        const __m512i axes = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), valid, id, s.neg_axes, 4);
        for (int a = 0; a < 3; ++a) {
            org[a] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), valid, id, s.org[a], 4);
            ninv[a] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), valid, id, s.ninv[a], 4);
            inv_far[a] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), valid, id, s.inv_far[a], 4);
            neg[a] = _mm512_test_epi32_mask(axes, _mm512_set1_epi32(1 << a));  // the near plane is hi
        }
        const __m512i lo = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), valid, id, s.tmin_bits, 4);
        const __m512i ntmax =
            _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), valid, id, s.neg_tmax_far, 4);
        for (int c = 0; c < children; ++c) {
            __m512i tn[3], ntf[3];
            for (int a = 0; a < 3; ++a) {
                const __m512 l = _mm512_set1_ps(lo_planes[a][c]), hp = _mm512_set1_ps(hi_planes[a][c]);
                const __m512 near = _mm512_mask_blend_ps(neg[a], l, hp),
                             far = _mm512_mask_blend_ps(neg[a], hp, l);
                tn[a] = _mm512_castps_si512(_mm512_mul_ps(_mm512_sub_ps(org[a], near), ninv[a]));
                ntf[a] = _mm512_castps_si512(_mm512_mul_ps(_mm512_sub_ps(org[a], far), inv_far[a]));
            }
            // The zero-masked forms: GCC 12 warns of the plain ones' undefined source.
            const __m512i entry = _mm512_maskz_max_epi32(valid, _mm512_maskz_max_epi32(valid, tn[1], tn[2]),
                                                         _mm512_maskz_max_epi32(valid, tn[0], lo));
            const __m512i neg_exit =
                _mm512_maskz_min_epu32(valid, _mm512_maskz_min_epu32(valid, ntf[1], ntf[2]),
                                       _mm512_maskz_min_epu32(valid, ntf[0], ntmax));
            // As bvh8_hits_avx512: entry + 0x7FFFFFFF <= neg_exit - 1, unsigned.
            sc.mask[g][c] = uint16_t(
                _mm512_mask_cmp_epu32_mask(valid, _mm512_add_epi32(entry, _mm512_set1_epi32(0x7FFFFFFF)),
                                           _mm512_sub_epi32(neg_exit, _mm512_set1_epi32(1)), _MM_CMPINT_LE));
            _mm512_store_si512(sc.entry[g][c], entry);
        }
    }
}

/// Sorts a ray's frontier farthest first (the traversal stack's order); few entries.
inline void sort_frontier(uint64_t* f, int n) {
    for (int i = 1; i < n; ++i) {
        const uint64_t in = f[i];
        int k = i;
        // Distances are non-negative: their bit patterns order like the floats.
        while (k > 0 && (f[k - 1] >> 32) < (in >> 32)) {
            f[k] = f[k - 1];
            --k;
        }
        f[k] = in;
    }
}

template <bool kAvx512>
__attribute__((always_inline)) inline void walk(const Bvh8& bvh, RayStream& s, StreamScratch& sc,
                                                RayStreamStats* stats) {
    const int n = s.size;
    for (int i = 0; i < n; ++i) sc.ids[i] = uint32_t(i);
    int top = 0, arena = n;
    sc.stack[top++] = StreamEntry{0, 0, 0, n, n};
    while (top > 0) {
        const StreamEntry e = sc.stack[--top];
        arena = e.arena_end;
        const Bvh8Node& node = bvh.node_at(e.ref);
        // Children fill the slots from the front (empty ones last).
        int children = 8;
        while (children > 0 && !node.has_child(children - 1)) --children;
        if (stats) {
            ++stats->node_visits[e.depth];
            stats->ray_node_tests[e.depth] += uint64_t(e.count);
        }
        const uint32_t* ids = sc.ids + e.first;
        if constexpr (kAvx512)
            test_children_avx512(node, children, s, ids, e.count, sc);
        else
            test_children_avx2(node, children, s, ids, e.count, sc);
        const int groups = (e.count + kGroupRays - 1) / kGroupRays;
        const int pushed = top;
        for (int c = 0; c < children; ++c) {
            const uint32_t ref = node.child[c];
            int hits = 0;
            for (int g = 0; g < groups; ++g) hits += std::popcount(unsigned(sc.mask[g][c]));
            if (hits == 0) continue;
            if (ref_count(ref) == 0 && hits >= kMinStreamListRays && e.depth + 1 <= kMaxStreamDepth) {
                const int first = arena;
                for (int g = 0; g < groups; ++g) {
                    if constexpr (kAvx512)
                        append_ids_avx512(sc.ids + arena, ids + kGroupRays * g, sc.mask[g][c]);
                    else
                        append_ids_avx2(sc.ids + arena, ids + kGroupRays * g, sc.mask[g][c]);
                    arena += std::popcount(unsigned(sc.mask[g][c]));
                }
                sc.stack[top++] = StreamEntry{ref, e.depth + 1, first, hits, 0};
                continue;
            }
            // The child goes to its rays' frontiers.
            for (int g = 0; g < groups; ++g) {
                if (!sc.mask[g][c]) continue;
                if constexpr (kAvx512)
                    append_frontier_avx512(s, ids + kGroupRays * g, sc.mask[g][c], sc.entry[g][c], ref);
                else
                    append_frontier(s, ids + kGroupRays * g, sc.mask[g][c], sc.entry[g][c], ref);
            }
        }
        // The children pushed above release the arena down to their siblings' end.
        for (int k = pushed; k < top; ++k) sc.stack[k].arena_end = arena;
    }
    for (int i = 0; i < n; ++i) {
        if (stats) {
            stats->frontier_entries += s.frontier_count[i];
            stats->overflows += s.overflow[i] ? 1 : 0;
        }
        sort_frontier(s.frontier[i], s.frontier_count[i]);
    }
    if (stats) stats->rays += uint64_t(n);
}

__attribute__((target("avx2"))) void walk_avx2(const Bvh8& bvh, RayStream& s, StreamScratch& sc,
                                               RayStreamStats* stats) {
    walk<false>(bvh, s, sc, stats);
}

__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) void walk_avx512(const Bvh8& bvh,
                                                                                    RayStream& s,
                                                                                    StreamScratch& sc,
                                                                                    RayStreamStats* stats) {
    walk<true>(bvh, s, sc, stats);
}

}  // namespace

void trace_stream_frontiers(const Bvh8& bvh, RayStream& s, RayStreamStats* stats) {
    thread_local std::unique_ptr<StreamScratch> scratch;  // per thread, kept: about 35 kB
    if (!scratch) scratch = std::make_unique<StreamScratch>();
    if (active_simd_path() == SimdPath::avx512)
        walk_avx512(bvh, s, *scratch, stats);
    else
        walk_avx2(bvh, s, *scratch, stats);
}

}  // namespace sahara
