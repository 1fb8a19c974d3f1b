#pragma once
/// Wide BVHs (the BVH8 of the wide8 layout) collapsed from the binary SAH tree: each
/// node holds the boxes of up to N children in structure-of-arrays form, so one ray
/// tests all children in one SIMD step (AVX; the SSE2 fallback tests an 8-wide node
/// as two halves). Which binary nodes are merged into one wide
/// node is chosen to minimise the summed area of the wide nodes (bvh_wide.cpp).
///
/// Traversal is ordered: the hit children are sorted by entry distance and
/// visited nearest first. Robustness is that of bvh_traverse.h: NaN from
/// 0 * inf (origin on a slab plane, zero direction component) is ignored, and
/// the far distance is enlarged by 1 + 2 gamma(3) (Ize, "Robust BVH Ray
/// Traversal", 2013). Unused child slots hold an empty box (lo = +inf,
/// hi = -inf), which no ray with a finite origin can hit.
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

#include <immintrin.h>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"

namespace sahara {

/// A child reference (BvhWideNode::child, and the traversal's stack entries): an inner
/// node's byte offset in BvhWide::nodes (a multiple of the node size, so its low
/// kLeafCountBits are 0), or a leaf, first << kLeafCountBits | count with count in
/// [1, kMaxWideLeafCount] (first: its first slot, or its first TriangleBlock4 in the block
/// layouts). The traversal's stack entries are then 8 bytes, one reference and one
/// distance, and one test of the low bits tells a leaf.
constexpr uint32_t kLeafCountBits = 6;
constexpr uint32_t kMaxWideLeafCount = (1u << kLeafCountBits) - 1;
/// Slots (and blocks) a leaf reference can start at: [0, kMaxWideLeafFirst].
constexpr uint32_t kMaxWideLeafFirst = 0xFFFFFFFFu >> kLeafCountBits;
inline uint32_t wide_leaf_ref(uint32_t first, uint32_t count) { return first << kLeafCountBits | count; }
/// A reference's leaf count; 0: an inner node.
inline uint32_t ref_count(uint32_t ref) { return ref & kMaxWideLeafCount; }
/// A leaf reference's first slot (or block).
inline uint32_t ref_first(uint32_t ref) { return ref >> kLeafCountBits; }

/// One N-wide node; child c is empty (child[c] == kNoNode), inner (child = the node's
/// byte offset) or a leaf (child = wide_leaf_ref(first, count)). The alignment pads it
/// to whole cache lines (the last one half used).
template <int N>
struct alignas(64) BvhWideNode {
    float lo_x[N], hi_x[N], lo_y[N], hi_y[N], lo_z[N], hi_z[N];  ///< 24 N bytes of child bounds
    uint32_t child[N];

    static constexpr int kWidth = N;
    bool has_child(int c) const { return child[c] != kNoNode; }
    /// Child c's leaf primitive count; 0 for an inner or empty child.
    uint32_t leaf_count(int c) const { return has_child(c) ? ref_count(child[c]) : 0; }
    /// Child c decoded for traversals that keep the count beside it (packets): a leaf's
    /// first slot (or block), an inner child's node offset.
    uint32_t child_index(int c) const { return leaf_count(c) ? ref_first(child[c]) : child[c]; }
};
using Bvh8Node = BvhWideNode<8>;
static_assert(sizeof(Bvh8Node) == 256, "four cache lines per node");
static_assert(sizeof(Bvh8Node) % (kMaxWideLeafCount + 1) == 0,
              "node offsets keep the low bits of a reference 0");

/// An N-wide BVH. `root` keeps the root box; a leaf root has no nodes.
template <int N>
struct BvhWide {
    BvhNode root{};
    std::vector<BvhWideNode<N>, AlignedAllocator<BvhWideNode<N>, 64>>
        nodes;  ///< nodes[0]: the root's children
    bool empty = true;

    /// An inner child holds its node's byte offset (index * sizeof(node)), not its
    /// index: the traversal's next node address is then one addition. The address
    /// depends on the node test just made, so a multiplication there would lengthen
    /// every step of the chain.
    static uint32_t offset_of(size_t index) { return uint32_t(index * sizeof(BvhWideNode<N>)); }
    static size_t index_of(uint32_t offset) { return offset / sizeof(BvhWideNode<N>); }
    const BvhWideNode<N>& node_at(uint32_t offset) const {
        return *reinterpret_cast<const BvhWideNode<N>*>(reinterpret_cast<const char*>(nodes.data()) + offset);
    }
    /// Offsets are 32-bit: at most 4 GiB of nodes (BVH8: 16.7M nodes, some 300M triangles).
    static constexpr size_t kMaxNodes = (size_t(1) << 32) / sizeof(BvhWideNode<N>);

    size_t bytes() const { return sizeof(BvhNode) + nodes.size() * sizeof(BvhWideNode<N>); }
};
using Bvh8 = BvhWide<8>;

/// Cost model of the collapse (bvh_wide.cpp): a wide node visit costs 1.
struct WideCollapse {
    /// A subtree of at most this many primitives (in contiguous slots) may become one
    /// leaf; 0 keeps the binary tree's leaves.
    uint32_t merge_leaves_up_to = 0;
    /// Cost of testing one leaf block of four primitives.
    double block_cost = 1.0;
};

/// Collapses a canonical binary Bvh (slots unchanged; nodes in depth-first order).
template <int N>
BvhWide<N> make_bvh_wide(const Bvh& bvh, const WideCollapse& opt = {});

/// Which instruction set the traversals run: the single-ray wide8 traversal (one body,
/// three instantiations) and the packet kernels (accel/packet.h) alike.
enum class SimdPath : uint8_t {
    sse2,    ///< baseline of every x86-64 CPU
    avx2,    ///< VEX encoding, 8-wide node tests in one AVX step
    avx512,  ///< the AVX2 code with AVX-512VL (32 vector registers) and its own 8-wide node step
};

namespace detail {
extern std::atomic<int> g_simd_path;  ///< -1 until the first call of active_simd_path()
}  // namespace detail
/// Reads SAHARA_SIMD and the CPU once (behind active_simd_path()); the one reader of
/// SAHARA_SIMD.
SimdPath init_simd_path();
/// The path in use: the widest the CPU has, unless force_simd_path() was called or the
/// environment variable SAHARA_SIMD=sse2|avx2|avx512 asks for a narrower one. SAHARA_SIMD
/// is a testing switch: it runs the fallback paths on a CPU that has wider ones (results
/// are the same on every path). One relaxed load per ray.
inline SimdPath active_simd_path() {
    const int p = detail::g_simd_path.load(std::memory_order_relaxed);
    return p >= 0 ? SimdPath(p) : init_simd_path();
}
/// Forces a path (tests); a path the CPU lacks falls back to the widest it has.
void force_simd_path(SimdPath path);
/// Undoes force_simd_path(): back to the CPU's and SAHARA_SIMD's choice.
void clear_forced_simd_path();
/// Whether this CPU can run the AVX2 path.
bool cpu_has_avx2();
/// Whether this CPU can run the AVX-512 path (F, VL, BW, DQ).
bool cpu_has_avx512();
/// The widest path this CPU runs.
SimdPath best_simd_path();
/// Every path this CPU runs, narrowest first (tests force each).
std::vector<SimdPath> runnable_simd_paths();
/// "sse2", "avx2" or "avx512".
const char* simd_path_name(SimdPath path);

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

/// What a leaf test inside the traversal's inner loop found.
enum class LeafResult : uint8_t {
    miss,
    hit,   ///< a hit: `tmax` lowered (closest hit) or the search may end (any hit)
    slow,  ///< not decided and nothing changed: the leaf needs the full test
};

/// Ordered traversal of an N-wide BVH, with the contract of traverse_bvh
/// (bvh_traverse.h): the nearest hit child is visited next, the others are
/// pushed farthest first. kAvx: 8-wide box tests in AVX (caller compiled for AVX2);
/// kAvx512: 8-wide nodes take the AVX-512 step (intersect_bvh8_compress_avx512).
/// kPairNodes (8-wide; closest hit on the AVX2 and AVX-512 steps, any hit on the AVX2
/// step): until the first hit, the inner node on top of the stack is tested in the same
/// step as `cur`, and the hit children of both go to the stack together
/// (AcceleratorOptions::node_pairing).
///
/// Leaves go first to `fast_leaf`, which must call no function: the inner loop
/// then holds no call, and GCC keeps what of the ray's box constants fits in
/// registers there (the AVX2 build: the origins; the inverse directions are read
/// as memory operands). With a call anywhere in the loop it would keep them all on
/// the stack, every vector register being caller-saved. A leaf it answers `slow`
/// goes to `slow_leaf` (the complete test: other primitive kinds, the scalar
/// fallback, the alpha test) in the outer loop.
///
/// fast_leaf(first, count, next_first, next_count, paired, tmax) also gets the
/// stack entry that would be visited next (next_count 0: none, or an inner node);
/// when it tests that leaf in the same step it sets `paired`, and the entry is
/// dropped from the stack.
template <bool kAnyHit, bool kAvx = false, bool kAvx512 = false, bool kPairNodes = false, int N,
          class Counters, class FastLeaf, class SlowLeaf>
__attribute__((always_inline)) inline bool traverse_wide(const BvhWide<N>& bvh, BvhRay& ray,
                                                         FastLeaf&& fast_leaf, SlowLeaf&& slow_leaf,
                                                         Counters& counters) {
    if (bvh.empty) return false;
    // No test of the root box: nodes[0] tests the root's children, which lie inside it.
    if (bvh.root.is_leaf()) {
        counters.on_prims(bvh.root.count);
        return slow_leaf(bvh.root.index, bvh.root.count, ray.tmax);
    }
    // A stack entry: a child reference and its entry distance, 8 bytes (the AVX-512 steps
    // write them as words: reference low, distance high).
    struct Entry {
        uint32_t ref;
        float t;
    };
    static_assert(sizeof(Entry) == 8);
    const char* const nodes = reinterpret_cast<const char*>(bvh.nodes.data());
    // Each node pushes at most N - 1 entries per level, plus slack. A paired step (any
    // kPairNodes form) pops one entry and pushes up to 2 N - 1, and pairs only while
    // top <= kPairMaxTop; above that the steps push N - 1 per level of one path down the
    // tree, so the stack stays below kPairMaxTop + 2 N + (N - 1) * kBvhMaxDepth.
    constexpr int kPairMaxTop = (N - 1) * kBvhMaxDepth;
    Entry stack[2 * (N - 1) * kBvhMaxDepth + 2 * N + 8];  // + 8: the AVX-512 any-hit step writes 8 entries
    int top = 0;
    bool found = false;
    Entry cur{0, ray.tmin};
    // tmax scaled for the far planes; changes only when a leaf lowers tmax.
    float tmax_far = ray.tmax * kRobustFarScale;
    // Inserts `in` among the entries pushed since `base`, which are sorted farthest deepest.
    auto push_sorted = [&](int base, Entry in) __attribute__((always_inline)) {
        int k = top++;
        while (k > base && stack[k - 1].t < in.t) {
            stack[k] = stack[k - 1];
            --k;
        }
        stack[k] = in;
    };
    // Puts the nearer of a and b into a without a branch: which of two hit children is
    // nearer is a coin toss for the predictor. Entry distances are at least tmin >= 0, so
    // their bit patterns order like the floats (were one negative, only the order of
    // visits would suffer, not the answer); on a tie, a stays.
    auto nearer_first = [](Entry & a, Entry & b) __attribute__((always_inline)) {
        const uint32_t ta = std::bit_cast<uint32_t>(a.t), tb = std::bit_cast<uint32_t>(b.t);
        const uint32_t swap = uint32_t(0) - uint32_t(tb < ta);
        const uint32_t dr = (a.ref ^ b.ref) & swap, dt = (ta ^ tb) & swap;
        a.ref ^= dr, b.ref ^= dr;
        a.t = std::bit_cast<float>(ta ^ dt), b.t = std::bit_cast<float>(tb ^ dt);
    };
    // Asks for the child boxes of the node at `p` (its first three cache lines; the fourth,
    // child links, is read only on a hit). The paired forms run on trees larger than the L2
    // cache (AcceleratorOptions::node_pairing), where a pushed node is often still in L3 or
    // memory when it is popped, so they prefetch every child they push. A leaf's reference
    // is not a node offset: that request is wasted, but it costs no branch (the address is
    // made in integers, as it may lie past the node array; a prefetch never faults).
    auto prefetch_planes = [nodes](uint32_t child) __attribute__((always_inline)) {
        const auto p = reinterpret_cast<const char*>(reinterpret_cast<uintptr_t>(nodes) + child);
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 64, _MM_HINT_T0);
        _mm_prefetch(p + 128, _MM_HINT_T0);
    };
    // Pops the nearest pending entry that can still hold a closer hit into `cur`.
    auto pop = [&]() __attribute__((always_inline)) {
        for (;;) {
            if (top == 0) return false;
            cur = stack[--top];
            // An occlusion ray's tmax never shrinks: every pushed entry is still in reach.
            if (kAnyHit || cur.t <= tmax_far) return true;
        }
    };
    for (;;) {
        // Made here, not before the loop: their registers then never live across a call.
        const WideRay<N, kAvx && N == 8> rw(ray);
        for (;;) {  // the inner loop: no calls
            if (const uint32_t count = ref_count(cur.ref)) {
                counters.on_prims(count);
                // The entry visited next, when it is a leaf, may be tested in the same step.
                uint32_t next = 0;
                if (top > 0 && (kAnyHit || stack[top - 1].t <= tmax_far)) next = stack[top - 1].ref;
                bool paired = false;
                const LeafResult r =
                    fast_leaf(ref_first(cur.ref), count, ref_first(next), ref_count(next), paired, ray.tmax);
                if (r == LeafResult::slow) break;
                if (paired) {
                    --top;
                    counters.on_prims(ref_count(next));
                }
                if (r == LeafResult::hit) {
                    if constexpr (kAnyHit) return true;
                    found = true;
                    tmax_far = ray.tmax * kRobustFarScale;
                }
            } else {
                const auto& n = *reinterpret_cast<const BvhWideNode<N>*>(nodes + cur.ref);  // node_at
                if constexpr (!std::is_same_v<Counters, NoTraversalCounters>)
                    for (int c = 0; c < N; ++c) counters.on_nodes(n.has_child(c) ? 1 : 0);
                if constexpr (kAvx512 && N == 8 && kAnyHit) {
                    const Bvh8HitChildren h = intersect_bvh8_entries_avx512(
                        n, rw.avx, ray.tmin, tmax_far, reinterpret_cast<uint64_t*>(&stack[top]));
                    if (h.mask) {
                        // The first hit child is visited next, the others stay pushed (the
                        // last one on top); no branch on the number of hits.
                        cur = Entry{h.ref0, 0.0f};
                        top += __builtin_popcount(h.mask) - 1;
                        continue;
                    }
                    if (!pop()) return found;
                    continue;
                } else if constexpr (kAvx512 && N == 8) {  // closest hit
                    // Until the first hit, an inner node on top of the stack is tested in the
                    // same step (intersect_bvh8_pair_avx512): before a hit nothing culls it,
                    // so it is visited anyway, unless a hit below `cur` comes first.
                    if (kPairNodes && !found && top > 0 && top <= kPairMaxTop &&
                        ref_count(stack[top - 1].ref) == 0 && stack[top - 1].t <= tmax_far) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) uint64_t hit[2 * N];
                        const Bvh8HitChildren h =
                            intersect_bvh8_pair_avx512(n, b, rw.avx, ray.tmin, tmax_far, hit);
                        if (h.mask) {
                            cur = Entry{h.ref0, h.t0};
                            const int base = top;
                            for (int i = 1; i < int(h.mask); ++i) {
                                prefetch_planes(uint32_t(hit[i]));
                                Entry in = std::bit_cast<Entry>(hit[i]);
                                nearer_first(cur, in);
                                push_sorted(base, in);
                            }
                            continue;
                        }
                        if (!pop()) return found;
                        continue;
                    }
                    alignas(32) uint32_t ref[N];
                    alignas(32) float t[N];
                    const Bvh8HitChildren h =
                        intersect_bvh8_compress_avx512(n, rw.avx, ray.tmin, tmax_far, ref, t);
                    if (h.mask) {
                        cur = Entry{h.ref0, h.t0};
                        if (!(h.mask & (h.mask - 1))) continue;  // one child hit
                        const int hits = __builtin_popcount(h.mask);
                        const int base = top;
                        for (int i = 1; i < hits; ++i) {
                            if constexpr (kPairNodes) {
                                prefetch_planes(ref[i]);
                            }
                            Entry in{ref[i], t[i]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        continue;
                    }
                    if (!pop()) return found;
                    continue;
                }
                if constexpr (kPairNodes && kAvx && !kAvx512 && N == 8 && kAnyHit) {
                    // Occlusion rays on the AVX2 step pair nodes too (nothing culls a pushed
                    // entry): the hit children of both pushed in slot order, b's beneath, the
                    // last of a's visited next. (Not on the AVX-512 step: pairing cannot keep
                    // that step's first-hit-first order, without which its shadow rays are slower.)
                    if (top > 0 && top <= kPairMaxTop && ref_count(stack[top - 1].ref) == 0) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) float ta[N], tb[N];
                        int ma = rw.test(n, ray.tmin, tmax_far, ta);
                        int mb = rw.test(b, ray.tmin, tmax_far, tb);
                        if (!(ma | mb)) {
                            if (!pop()) return found;
                            continue;
                        }
                        for (; mb; mb &= mb - 1)
                            stack[top++] = Entry{b.child[__builtin_ctz(unsigned(mb))], 0.0f};
                        for (; ma; ma &= ma - 1)
                            stack[top++] = Entry{n.child[__builtin_ctz(unsigned(ma))], 0.0f};
                        cur = stack[--top];
                        continue;
                    }
                }
                if constexpr (kPairNodes && kAvx && !kAvx512 && N == 8 && !kAnyHit) {
                    // The AVX2 form of the AVX-512 step's node pairing: both nodes' tests,
                    // then their hit children sorted into the stack as one batch.
                    if (!found && top > 0 && top <= kPairMaxTop && ref_count(stack[top - 1].ref) == 0 &&
                        stack[top - 1].t <= tmax_far) {
                        const auto& b = *reinterpret_cast<const BvhWideNode<N>*>(nodes + stack[--top].ref);
                        alignas(32) float ta[N], tb[N];
                        int ma = rw.test(n, ray.tmin, tmax_far, ta);
                        int mb = rw.test(b, ray.tmin, tmax_far, tb);
                        if (!(ma | mb)) {
                            if (!pop()) return found;
                            continue;
                        }
                        if (ma) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(ma)));
                            ma &= ma - 1;
                            cur = Entry{n.child[c], ta[c]};
                        } else {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(mb)));
                            mb &= mb - 1;
                            cur = Entry{b.child[c], tb[c]};
                        }
                        const int base = top;
                        for (; ma; ma &= ma - 1) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(ma)));
                            prefetch_planes(n.child[c]);
                            Entry in{n.child[c], ta[c]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        for (; mb; mb &= mb - 1) {
                            const unsigned c = unsigned(__builtin_ctz(unsigned(mb)));
                            prefetch_planes(b.child[c]);
                            Entry in{b.child[c], tb[c]};
                            nearer_first(cur, in);
                            push_sorted(base, in);
                        }
                        continue;
                    }
                }
                alignas(32) float t[N];
                int mask = rw.test(n, ray.tmin, tmax_far, t);
                if (mask) {
                    // Unsigned: the child's address then needs no sign extension.
                    unsigned c = unsigned(__builtin_ctz(unsigned(mask)));
                    mask &= mask - 1;
                    cur = Entry{n.child[c], t[c]};
                    if (!mask) continue;  // one child hit: no ordering, no stack
                    if constexpr (kAnyHit) {
                        // Any hit ends the search, so order buys little: push in child order
                        // (Embree's occlusion traversal does the same), the last becomes `cur`.
                        do {
                            stack[top++] = cur;
                            c = unsigned(__builtin_ctz(unsigned(mask)));
                            mask &= mask - 1;
                            cur = Entry{n.child[c], 0.0f};
                        } while (mask);
                        continue;
                    }
                    // Insert the others into the stack top sorted by distance (farthest
                    // deepest); the nearest of all becomes `cur`, without a branch as in
                    // the AVX-512 step (here a branch would be no faster).
                    const int base = top;
                    do {
                        c = unsigned(__builtin_ctz(unsigned(mask)));
                        mask &= mask - 1;
                        Entry in{n.child[c], t[c]};
                        nearer_first(cur, in);
                        push_sorted(base, in);
                    } while (mask);
                    continue;
                }
            }
            if (!pop()) return found;
        }
        if (slow_leaf(ref_first(cur.ref), ref_count(cur.ref), ray.tmax)) {
            if constexpr (kAnyHit) return true;
            found = true;
            tmax_far = ray.tmax * kRobustFarScale;
        }
        if (!pop()) return found;
    }
}

}  // namespace sahara
