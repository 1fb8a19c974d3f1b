#pragma once
// Packet traversal kernel over the wide tree, as templates on the instruction set:
// kIsa 128 (SSE2, four 4-lane quarters) or 512 (AVX-512F, one 16-lane register); the
// AVX2 path has its own kernel (packet_wide8.cpp). packet.cpp includes this header for
// PacketContext and the entry points; packet_sse2.cpp and packet_avx512.cpp include it
// inside their `#pragma GCC target` regions, so the templates carry that target, and
// instantiate trace_packet there. Every function is a template on kIsa, so the two
// translation units never share a symbol compiled for different targets.
//
// The arithmetic uses GCC vector extensions of 16 floats, which the compiler maps onto
// the target's widest registers; only the mask extraction needs intrinsics.
//
// Bit-identity with the single-ray code: each lane performs the float operations of
// intersect_wide_sse / intersect_bvh_node (box tests) and TriangleVerts::intersect
// (geometry/triangle.h) in the same order, with fp-contract off, so no fused multiply-add
// changes a rounding.
#include <immintrin.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>

#include "accel/packet.h"
#include "scene/accelerator.h"

// The kernels pass 64-byte vectors between always-inline helpers only, so
// GCC's note that such arguments change the ABI without AVX-512 is moot.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace sahara {

/// What every ISA's kernel needs: the packet, the tree, and the permutation
/// and plane choice shared by all active rays (see packet_eligible in packet.cpp).
struct PacketContext {
    const RayPacket* rays;
    const TriangleBlock4* blocks;
    const Accelerator* accel;
    const uint8_t* one_sided;  ///< per triangle: 1 when one-sided (Accelerator::culls); null: none is
    int kx, ky, kz;            ///< watertight-test axis permutation, common to all active rays
    int neg[3];                ///< direction sign per axis, common to all active rays
    int near_off[3];           ///< offset of each axis's near planes in a node, in units of N floats
    int far_off[3];            ///< offset of each axis's far planes, in units of N floats
    int first;                 ///< first active lane
};

namespace packet_kernel {

inline constexpr int kSse2 = 128;
inline constexpr int kAvx512 = 512;

using F = float __attribute__((vector_size(64)));
using I = int32_t __attribute__((vector_size(64)));

template <int kIsa>
[[gnu::always_inline]] inline uint32_t mask_of(I c) {
    if constexpr (kIsa == 512) {
        __m512i x;
        std::memcpy(&x, &c, sizeof x);
        return uint32_t(_mm512_cmplt_epi32_mask(x, _mm512_setzero_si512()));
    } else {
        __m128 x[4];
        std::memcpy(x, &c, sizeof x);
        return uint32_t(_mm_movemask_ps(x[0])) | uint32_t(_mm_movemask_ps(x[1])) << 4 |
               uint32_t(_mm_movemask_ps(x[2])) << 8 | uint32_t(_mm_movemask_ps(x[3])) << 12;
    }
}

template <int kIsa>
[[gnu::always_inline]] inline F load(const float* p) {
    F v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

template <int kIsa>
[[gnu::always_inline]] inline F splat(float x) {
    return F{} + x;
}

/// Lane-wise c ? a : b as bit operations (GCC lowers a vector `?:` wider than
/// the registers lane by lane; the bit form stays in registers).
template <int kIsa>
[[gnu::always_inline]] inline F select(I c, F a, F b) {
    if constexpr (kIsa == 512) {
        return c ? a : b;  // one masked blend
    } else {
        return std::bit_cast<F>((std::bit_cast<I>(a) & c) | (std::bit_cast<I>(b) & ~c));
    }
}
template <int kIsa>
[[gnu::always_inline]] inline I select(I c, I a, I b) {
    if constexpr (kIsa == 512) {
        return c ? a : b;
    } else {
        return (a & c) | (b & ~c);
    }
}

/// a > b ? a : b lane-wise (b when either is NaN), as maxps. AVX-512 lowers
/// the vector `?:` natively; narrower ISAs get the intrinsic per register.
template <int kIsa>
[[gnu::always_inline]] inline F vmax(F a, F b) {
    if constexpr (kIsa == 512) {
        return a > b ? a : b;
    } else {
        constexpr int kParts = sizeof(F) / sizeof(__m128);
        __m128 x[kParts], y[kParts];
        std::memcpy(x, &a, sizeof x);
        std::memcpy(y, &b, sizeof y);
        for (int k = 0; k < kParts; ++k) x[k] = _mm_max_ps(x[k], y[k]);
        std::memcpy(&a, x, sizeof a);
        return a;
    }
}

/// a < b ? a : b lane-wise (b when either is NaN), as minps.
template <int kIsa>
[[gnu::always_inline]] inline F vmin(F a, F b) {
    if constexpr (kIsa == 512) {
        return a < b ? a : b;
    } else {
        constexpr int kParts = sizeof(F) / sizeof(__m128);
        __m128 x[kParts], y[kParts];
        std::memcpy(x, &a, sizeof x);
        std::memcpy(y, &b, sizeof y);
        for (int k = 0; k < kParts; ++k) x[k] = _mm_min_ps(x[k], y[k]);
        std::memcpy(&a, x, sizeof a);
        return a;
    }
}

/// All-ones lanes where bit i of `bits` is set.
template <int kIsa>
[[gnu::always_inline]] inline I lanes_of(uint32_t bits) {
    const I lane_bit = {1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384, 32768};
    return (lane_bit & int32_t(bits)) != 0;
}

/// The packet's state: per-ray box-test and watertight-test constants and the running nearest hit.
struct alignas(64) State {
    F org[3], inv[3], tmin, tmax;
    F ox, oy, oz, sx, sy, sz;  ///< origin in the common (kx, ky, kz) order; shear constants
    F hu, hv;
    I prim;
};

/// Slab test of one box against every lane; `near`/`far` are the box's planes
/// per axis as seen by the packet's common direction signs. Same operations
/// as intersect_wide_sse per lane.
template <int kIsa>
[[gnu::always_inline]] inline uint32_t box_test(const State& s, const float near[3], const float far[3],
                                                F& t_near) {
    F t0 = s.tmin, t1 = s.tmax;
    for (int a = 0; a < 3; ++a) {
        const F tn = (splat<kIsa>(near[a]) - s.org[a]) * s.inv[a];
        const F tf = (splat<kIsa>(far[a]) - s.org[a]) * s.inv[a];
        t0 = vmax<kIsa>(tn, t0);  // NaN tn leaves t0 (the NaN-ignoring order)
        t1 = vmin<kIsa>(tf, t1);
    }
    t_near = t0;
    return mask_of<kIsa>(t0 <= t1 * kRobustFarScale);
}

/// Lane i takes (t, prim, u, v) where `take` is set.
template <int kIsa>
[[gnu::always_inline]] inline void take_hits(State& s, I take, F t, int32_t prim, F u, F v) {
    s.tmax = select<kIsa>(take, t, s.tmax);
    s.prim = select<kIsa>(take, I{} + prim, s.prim);
    s.hu = select<kIsa>(take, u, s.hu);
    s.hv = select<kIsa>(take, v, s.hv);
}

/// Lane i takes a scalar hit.
template <int kIsa>
[[gnu::always_inline]] inline void take_hit(State& s, int i, const Hit& h) {
    s.tmax[i] = h.t;
    s.prim[i] = int32_t(h.prim);
    s.hu[i] = h.u;
    s.hv[i] = h.v;
}

/// The rays of `mask` that meet the front of triangle lane `l` of `b` (the float
/// operations of Accelerator::culls, so single rays and packets agree).
template <int kIsa>
[[gnu::always_inline]] inline uint32_t front_facing_rays(const PacketContext& c, const TriangleBlock4& b,
                                                         int l, uint32_t mask) {
    const Vec3 a(b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]);
    const Vec3 n = cross(Vec3(b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]) - a,
                         Vec3(b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]) - a);
    const F d = splat<kIsa>(n.x) * load<kIsa>(c.rays->dir[0]) +
                splat<kIsa>(n.y) * load<kIsa>(c.rays->dir[1]) + splat<kIsa>(n.z) * load<kIsa>(c.rays->dir[2]);
    return mask & ~mask_of<kIsa>(d >= F{});  // NaN counts as the front, as in culls
}

/// One triangle (lane `l` of `b`, leaf slot `slot`) against the rays of `mask`.
template <int kIsa>
[[gnu::always_inline]] inline void test_triangle(State& s, const PacketContext& c, const TriangleBlock4& b,
                                                 int l, uint32_t mask) {
    // Rays behind a one-sided triangle pass through it: they are not tested.
    if (c.one_sided && c.one_sided[prim_index(b.slot[l])]) {
        mask = front_facing_rays<kIsa>(c, b, l, mask);
        if (!mask) return;
    }
    F x[3], y[3], z[3];
    for (int v = 0; v < 3; ++v) {
        z[v] = splat<kIsa>(b.p[v][c.kz][l]) - s.oz;
        x[v] = (splat<kIsa>(b.p[v][c.kx][l]) - s.ox) - s.sx * z[v];
        y[v] = (splat<kIsa>(b.p[v][c.ky][l]) - s.oy) - s.sy * z[v];
    }
    const F u = x[2] * y[1] - y[2] * x[1];
    const F v = x[0] * y[2] - y[0] * x[2];
    const F w = x[1] * y[0] - y[1] * x[0];
    const F zero = F{};
    const uint32_t exact_zero = mask_of<kIsa>((u == zero) | (v == zero) | (w == zero)) & mask;
    const I any_neg = (u < zero) | (v < zero) | (w < zero);
    const I any_pos = (u > zero) | (v > zero) | (w > zero);
    const F det = (u + v) + w;
    const F t_scaled = s.sz * ((u * z[0] + v * z[1]) + w * z[2]);  // as TriangleVerts::intersect
    const I sign = std::bit_cast<I>(det) & int32_t(0x80000000u);
    const F abs_det = std::bit_cast<F>(std::bit_cast<I>(det) ^ sign);
    const F t_signed = std::bit_cast<F>(std::bit_cast<I>(t_scaled) ^ sign);
    // det != 0 needs no test: the lanes kept have u, v, w non-zero and of one sign.
    const I ok = ~(any_neg & any_pos) & (t_signed > s.tmin * abs_det) & (t_signed < s.tmax * abs_det);
    const uint32_t bits = mask_of<kIsa>(ok) & mask & ~exact_zero;
    uint32_t redo = exact_zero;
    const uint32_t id = b.slot[l];  // a triangle lane holds its primitive id
    if (bits) {
        const F inv_det = 1.0f / det;
        const F t = t_scaled * inv_det;
        // Rounding of the division can push t onto the interval's boundary.
        I take = lanes_of<kIsa>(bits) & (t > s.tmin) & (t < s.tmax);
        // A triangle wholly ahead of the origin along the dominant axis is hit at t > 0; on
        // one that is not, a t within its rounding bound of 0 is decided by the scalar test.
        const I dz_sign = std::bit_cast<I>(s.sz) & int32_t(0x80000000u);
        const auto flip = [&](F f) __attribute__((always_inline)) {
            return std::bit_cast<F>(std::bit_cast<I>(f) ^ dz_sign);
        };
        const F nearest = vmin<kIsa>(vmin<kIsa>(flip(z[0]), flip(z[1])), flip(z[2]));
        if (const uint32_t straddling = mask_of<kIsa>(take & ~(nearest > zero))) {
            const auto max_abs = [](const F a[3]) __attribute__((always_inline)) {
                const auto abs = [](F f) { return std::bit_cast<F>(std::bit_cast<I>(f) & 0x7FFFFFFF); };
                return vmax<kIsa>(vmax<kIsa>(abs(a[0]), abs(a[1])), abs(a[2]));
            };
            F bound;
            t_scaled_error_bound(max_abs(x), max_abs(y), max_abs(z), abs_det, flip(s.sz), bound);
            const uint32_t near_zero = straddling & ~mask_of<kIsa>(t_signed > bound);
            take &= ~lanes_of<kIsa>(near_zero);
            redo |= near_zero;
        }
        take_hits<kIsa>(s, take, t, int32_t(id), v * inv_det, w * inv_det);
    }
    // Lanes left to the scalar test (double fallback included).
    for (uint32_t m = redo; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        Ray r = c.rays->ray(i);
        const TriangleRay tr(r);
        const TriangleVerts tri{{{b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]},
                                 {b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]},
                                 {b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]}}};
        if (const std::optional<ShapeHit> th = tri.intersect(tr, s.tmin[i], s.tmax[i]))
            take_hit<kIsa>(s, i, Hit{th->t, id, th->u, th->v});
    }
}

/// The leaf blocks [first, first + ceil(count / 4)) against the rays of `mask`:
/// per block, triangle lanes in order, then other kinds per ray (the order of test_blocks).
template <int kIsa>
[[gnu::always_inline]] inline void test_leaf(State& s, const PacketContext& c, uint32_t first, uint32_t count,
                                             uint32_t mask) {
    for (uint32_t bi = first; bi < first + (count + 3) / 4; ++bi) {
        const TriangleBlock4& b = c.blocks[bi];
        uint32_t other = 0;
        for (int l = 0; l < 4; ++l) {
            const uint32_t slot = b.slot[l];
            if (slot == TriangleBlock4::kEmptyLane) continue;
            if (slot & TriangleBlock4::kOtherKind)
                other |= 1u << l;
            else
                test_triangle<kIsa>(s, c, b, l, mask);
        }
        for (; other; other &= other - 1) {
            const uint32_t slot = b.slot[__builtin_ctz(other)] & ~TriangleBlock4::kOtherKind;
            for (uint32_t m = mask; m; m &= m - 1) {
                const int i = __builtin_ctz(m);
                Ray r = c.rays->ray(i);
                r.tmax = s.tmax[i];
                Hit h;
                if (c.accel->intersect_slot(r, slot, h)) take_hit<kIsa>(s, i, h);
            }
        }
    }
}

/// Sets up the per-ray constants of the active lanes (inactive lanes copy lane `first`).
template <int kIsa>
[[gnu::always_inline]] inline void init_state(State& s, const PacketContext& c) {
    const RayPacket& p = *c.rays;
    const I act = lanes_of<kIsa>(p.active);
    for (int a = 0; a < 3; ++a) {
        s.org[a] = select<kIsa>(act, load<kIsa>(p.org[a]), splat<kIsa>(p.org[a][c.first]));
        const F d = select<kIsa>(act, load<kIsa>(p.dir[a]), splat<kIsa>(p.dir[a][c.first]));
        s.inv[a] = 1.0f / d;  // +-inf for +-0, as in BvhRay
    }
    s.tmin = select<kIsa>(act, load<kIsa>(p.tmin), splat<kIsa>(p.tmin[c.first]));
    s.tmax = select<kIsa>(act, load<kIsa>(p.tmax), splat<kIsa>(p.tmax[c.first]));
    const F dx = select<kIsa>(act, load<kIsa>(p.dir[c.kx]), splat<kIsa>(p.dir[c.kx][c.first]));
    const F dy = select<kIsa>(act, load<kIsa>(p.dir[c.ky]), splat<kIsa>(p.dir[c.ky][c.first]));
    const F dz = select<kIsa>(act, load<kIsa>(p.dir[c.kz]), splat<kIsa>(p.dir[c.kz][c.first]));
    s.ox = s.org[c.kx], s.oy = s.org[c.ky], s.oz = s.org[c.kz];
    s.sz = 1.0f / dz, s.sx = dx * s.sz, s.sy = dy * s.sz;  // as in TriangleRay::shear
    s.hu = s.hv = F{};
    s.prim = I{} + int32_t(kNoPrim);
}

/// A pending subtree: node or leaf, the rays that entered its box and their entry distances.
struct PacketEntry {
    uint32_t index, count, mask;
    float order;  ///< entry distance of a representative ray (ordering only)
};

/// The rays that enter the root's box.
template <int kIsa, int N>
[[gnu::always_inline]] inline uint32_t root_mask(const State& s, const PacketContext& c,
                                                 const BvhWide<N>& bvh) {
    float near[3], far[3];
    for (int a = 0; a < 3; ++a) {
        near[a] = bvh.root.bounds[2 * a + c.neg[a]];
        far[a] = bvh.root.bounds[2 * a + 1 - c.neg[a]];
    }
    F tn;
    return box_test<kIsa>(s, near, far, tn);
}

/// Copies the nearest hits out; a lane without one gets t = infinity.
template <int kIsa>
[[gnu::always_inline]] inline void store_hits(const State& s, HitPacket& out) {
    const I hit = s.prim != int32_t(kNoPrim);
    const F t = select<kIsa>(hit, s.tmax, splat<kIsa>(kInfinity));
    std::memcpy(out.t, &t, sizeof t);
    std::memcpy(out.u, &s.hu, sizeof s.hu);
    std::memcpy(out.v, &s.hv, sizeof s.hv);
    std::memcpy(out.prim, &s.prim, sizeof s.prim);
}

/// Nearest hits of the active rays over an N-wide tree; see Accelerator::intersect_packet.
/// A traversal kernel, long on purpose (about 65 lines): the node step, the child
/// ordering and the pop share the packet state in one body, which GCC keeps in
/// registers only while nothing in the loop is an out-of-line call.
template <int kIsa, int N>
void trace_packet(const PacketContext& c, const BvhWide<N>& bvh, HitPacket& out) {
    State s;
    init_state<kIsa>(s, c);
    uint32_t mask = c.rays->active & root_mask<kIsa>(s, c, bvh);
    // nodes[0] holds the root's children; a leaf root's index is its first block.
    PacketEntry cur{bvh.root.is_leaf() ? bvh.root.index : 0u, bvh.root.is_leaf() ? bvh.root.count : 0u, mask,
                    0.0f};
    PacketEntry stack[(N - 1) * kBvhMaxDepth + 4];
    F stack_t[(N - 1) * kBvhMaxDepth + 4];
    int top = 0;
    while (mask) {
        if (cur.count) {
            test_leaf<kIsa>(s, c, cur.index, cur.count, cur.mask);
        } else {
            const BvhWideNode<N>& n = bvh.node_at(cur.index);
            const float* base = reinterpret_cast<const float*>(&n);
            PacketEntry hit[N];
            F hit_t[N];
            int hits = 0;
            for (int k = 0; k < N; ++k) {
                if (!n.has_child(k)) continue;
                float near[3], far[3];
                for (int a = 0; a < 3; ++a) {
                    near[a] = base[N * c.near_off[a] + k];
                    far[a] = base[N * c.far_off[a] + k];
                }
                F tn;
                const uint32_t m = box_test<kIsa>(s, near, far, tn) & cur.mask;
                if (!m) continue;
                // Insertion by the representative distance, nearest last.
                const PacketEntry e{n.child_index(k), n.leaf_count(k), m, tn[__builtin_ctz(m)]};
                int j = hits++;
                while (j > 0 && hit[j - 1].order < e.order) {
                    hit[j] = hit[j - 1];
                    hit_t[j] = hit_t[j - 1];
                    --j;
                }
                hit[j] = e;
                hit_t[j] = tn;
            }
            if (hits) {
                for (int j = 0; j < hits - 1; ++j) {
                    stack[top] = hit[j];
                    stack_t[top++] = hit_t[j];
                }
                cur = hit[hits - 1];
                continue;
            }
        }
        // Pop the nearest pending entry that some ray can still reach (per ray, as the single-ray pop).
        for (;;) {
            if (top == 0) {
                mask = 0;
                break;
            }
            --top;
            const uint32_t m = stack[top].mask & mask_of<kIsa>(stack_t[top] <= s.tmax * kRobustFarScale);
            if (m) {
                cur = stack[top];
                cur.mask = m;
                break;
            }
        }
    }
    store_hits<kIsa>(s, out);
}

// Instantiated once each, in packet_sse2.cpp and packet_avx512.cpp.
extern template void trace_packet<kSse2, 8>(const PacketContext&, const BvhWide<8>&, HitPacket&);
extern template void trace_packet<kAvx512, 8>(const PacketContext&, const BvhWide<8>&, HitPacket&);

}  // namespace packet_kernel
}  // namespace sahara
