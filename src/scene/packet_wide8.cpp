// 16-ray packets over the wide8 tree without a 16-lane register file (AVX2):
// the packet shares one traversal (stack, child ordering, node fetches) and
// inner nodes are tested once for the whole packet against its frustum, i.e.
// interval bounds on the rays' origins and inverse directions (the interval
// test of Wald, Boulos and Shirley, "Ray Tracing Deformable Scenes Using
// Dynamic Bounding Volume Hierarchies", 2007), all eight children in one AVX
// step. Only at a leaf are the rays tested one by one: each ray's own box test
// of the leaf (sixteen rays in two AVX steps, the single-ray operations lane by
// lane), then its own leaf-triangle test for the rays that enter.
//
// Hits equal intersect()'s: float rounding is monotonic, so the frustum's entry
// distance is at most and its exit distance at least every ray's own computed
// value, and a ray reaches every leaf its own traversal would (possibly more);
// the leaf tests are the single-ray ones. Only which of two primitives at
// exactly the same distance wins may differ.
#include <immintrin.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "scene/accelerator.h"
#include "scene/leaf_blocks.inl"
#include "accel/packet.h"

namespace sahara {

namespace {

/// The packet's bounds for the frustum test of one axis: the origin bound that gives the
/// smallest near-plane and the largest far-plane distance, and the inverse-direction range.
struct FrustumAxis {
    __m256 o_near, o_far, inv_lo, inv_hi;
    uint32_t near_off, far_off;  ///< byte offsets of the near and far planes in a Bvh8Node
};

/// Lower (kNear) or upper bound of fl(fl(plane - o) * inv) over every ray of the
/// packet, for each of a node's eight children. Rounding is monotonic, so the
/// bound taken at the corner origin and at both inverse-direction extremes holds
/// for every ray's own computed distance. A 0 * inf corner (a ray may lie in the
/// slab plane with a zero direction component) makes the lane NaN, which the
/// caller's min/max ignore, as the single-ray test ignores that slab.
template <bool kNear>
__attribute__((target("avx2"), always_inline)) inline __m256 frustum_plane(const char* node,
                                                                           const FrustumAxis& a) {
    const __m256 plane =
        _mm256_load_ps(reinterpret_cast<const float*>(node + (kNear ? a.near_off : a.far_off)));
    const __m256 x = _mm256_sub_ps(plane, kNear ? a.o_near : a.o_far);
    const __m256 p0 = _mm256_mul_ps(x, a.inv_lo), p1 = _mm256_mul_ps(x, a.inv_hi);
    const __m256 nan = _mm256_cmp_ps(p0, p1, _CMP_UNORD_Q);
    return _mm256_or_ps(kNear ? _mm256_min_ps(p0, p1) : _mm256_max_ps(p0, p1), nan);
}

/// The largest of 16 floats (none NaN).
__attribute__((target("avx2"), always_inline)) inline float max16(const float* v) {
    __m256 m = _mm256_max_ps(_mm256_load_ps(v), _mm256_load_ps(v + 8));
    m = _mm256_max_ps(m, _mm256_permute2f128_ps(m, m, 1));
    m = _mm256_max_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    return _mm_cvtss_f32(_mm256_castps256_ps128(_mm256_max_ps(m, _mm256_shuffle_ps(m, m, 1))));
}

/// The smallest of 16 floats (none NaN).
__attribute__((target("avx2"), always_inline)) inline float min16(const float* v) {
    __m256 m = _mm256_min_ps(_mm256_load_ps(v), _mm256_load_ps(v + 8));
    m = _mm256_min_ps(m, _mm256_permute2f128_ps(m, m, 1));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    return _mm_cvtss_f32(_mm256_castps256_ps128(_mm256_min_ps(m, _mm256_shuffle_ps(m, m, 1))));
}

/// A packet's rays in structure-of-arrays form for the per-ray leaf-box test.
struct PacketBoxRays {
    alignas(32) float org[3][kPacketSize];
    alignas(32) float inv[3][kPacketSize];
    alignas(32) float tmin[kPacketSize];
    alignas(32) float tmax_scaled[kPacketSize];  ///< tmax * kRobustFarScale; -inf in inactive lanes
    int neg[3];                                  ///< direction signs, shared by the packet
};

/// The rays whose own box test of child `lane` of `n` hits: the single-ray
/// operations (bvh_wide.h) lane by lane, sixteen rays in two AVX steps.
__attribute__((target("avx2"), always_inline)) inline uint32_t rays_in_box(const PacketBoxRays& r,
                                                                           const Bvh8Node& n, int lane) {
    const float* planes = n.lo_x;  // lo_x, hi_x, lo_y, hi_y, lo_z, hi_z: 8 floats each
    uint32_t hit = 0;
    for (int h = 0; h < 2; ++h) {
        __m256 t0 = _mm256_load_ps(r.tmin + 8 * h), t1 = _mm256_set1_ps(kInfinity);
        for (int a = 0; a < 3; ++a) {
            const __m256 o = _mm256_load_ps(r.org[a] + 8 * h), iv = _mm256_load_ps(r.inv[a] + 8 * h);
            const __m256 near = _mm256_set1_ps(planes[(2 * a + r.neg[a]) * 8 + lane]);
            const __m256 far = _mm256_set1_ps(planes[(2 * a + 1 - r.neg[a]) * 8 + lane]);
            t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(near, o), iv), t0);
            t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(far, o), iv), t1);
        }
        // The single ray compares with min(t1, tmax) * scale; t1 * scale and tmax * scale
        // taken apart round the same (scaling is monotonic), and tmax * scale is stored.
        const __m256 far_t = _mm256_min_ps(_mm256_mul_ps(t1, _mm256_set1_ps(kRobustFarScale)),
                                           _mm256_load_ps(r.tmax_scaled + 8 * h));
        hit |= uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(t0, far_t, _CMP_LE_OQ))) << (8 * h);
    }
    return hit;
}

}  // namespace

// A traversal kernel, long on purpose (about 145 lines): the setup of the per-ray and
// frustum constants, the frustum node step and the per-ray leaf step share those
// constants in one body, where they stay in registers and on the stack frame; split
// into out-of-line helpers they would be passed and reloaded on every node.
__attribute__((target("avx2"))) void Accelerator::trace_packet8_avx2(const RayPacket& p,
                                                                     HitPacket& out) const {
    // Per-lane single-ray constants; inactive lanes are never read.
    Ray rays[kPacketSize];
    TriangleRay tr[kPacketSize];
    Hit hits[kPacketSize];
    // Structure-of-arrays copies for the per-ray leaf-box test; inactive lanes repeat the
    // first active ray, so they widen no bound below. The divisions are the single ray's
    // (BvhRay, TriangleRay), eight lanes at a time.
    PacketBoxRays sr;
    alignas(32) float dir[3][kPacketSize];
    const int first = std::countr_zero(p.active);
    std::memcpy(sr.org, p.org, sizeof(sr.org));
    std::memcpy(dir, p.dir, sizeof(dir));
    std::memcpy(sr.tmin, p.tmin, sizeof(sr.tmin));
    for (uint32_t m = ~p.active & 0xFFFFu; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        for (int a = 0; a < 3; ++a) sr.org[a][i] = p.org[a][first], dir[a][i] = p.dir[a][first];
        sr.tmin[i] = p.tmin[first];
    }
    const TriangleRay first_tr(p.ray(first));  // packet_eligible: every ray has its permutation
    const int kx = first_tr.kx, ky = first_tr.ky, kz = first_tr.kz;
    alignas(32) float sx[kPacketSize], sy[kPacketSize], sz[kPacketSize];
    const __m256 one = _mm256_set1_ps(1.0f);
    for (int h = 0; h < kPacketSize; h += 8) {
        for (int a = 0; a < 3; ++a)
            _mm256_store_ps(sr.inv[a] + h, _mm256_div_ps(one, _mm256_load_ps(dir[a] + h)));
        const __m256 inv_dz = _mm256_load_ps(sr.inv[kz] + h);  // TriangleRay::shear
        _mm256_store_ps(sx + h, _mm256_mul_ps(_mm256_load_ps(dir[kx] + h), inv_dz));
        _mm256_store_ps(sy + h, _mm256_mul_ps(_mm256_load_ps(dir[ky] + h), inv_dz));
        _mm256_store_ps(sz + h, inv_dz);
        _mm256_store_ps(sr.tmax_scaled + h,
                        _mm256_mul_ps(_mm256_load_ps(p.tmax + h), _mm256_set1_ps(kRobustFarScale)));
    }
    for (uint32_t m = p.active; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        rays[i] = p.ray(i);
        tr[i] = first_tr;
        for (int a = 0; a < 3; ++a) tr[i].org[a] = p.org[a][i];
        tr[i].sx = sx[i], tr[i].sy = sy[i], tr[i].sz = sz[i];
    }
    for (uint32_t m = ~p.active & 0xFFFFu; m; m &= m - 1) sr.tmax_scaled[std::countr_zero(m)] = -kInfinity;
    // The frustum: per axis the extreme origins and inverse directions of the packet's rays
    // (packet_eligible: all share their direction signs).
    FrustumAxis fa[3];
    const float tmin_lo = min16(sr.tmin);
    for (int a = 0; a < 3; ++a) {
        const float o_lo = min16(sr.org[a]), o_hi = max16(sr.org[a]);
        const float i_lo = min16(sr.inv[a]), i_hi = max16(sr.inv[a]);
        // Positive direction: distance grows with plane - o, so the nearest near plane is
        // seen from the largest origin; negative: from the smallest.
        const int neg = std::signbit(p.dir[a][first]) ? 1 : 0;  // as BvhRay::neg
        sr.neg[a] = neg;
        fa[a].o_near = _mm256_set1_ps(neg ? o_lo : o_hi);
        fa[a].o_far = _mm256_set1_ps(neg ? o_hi : o_lo);
        fa[a].inv_lo = _mm256_set1_ps(i_lo);
        fa[a].inv_hi = _mm256_set1_ps(i_hi);
        fa[a].near_off = uint32_t(64 * a + 32 * neg);
        fa[a].far_off = uint32_t(64 * a + 32 * (1 - neg));
    }
    const __m256 t_lo = _mm256_set1_ps(tmin_lo);
    float reach = max16(sr.tmax_scaled);  // the largest scaled tmax of the packet

    // Tests the rays in `mask` against a leaf's triangles; lowers their tmax and the reach.
    auto leaf = [&](uint32_t first_block, uint32_t count, uint32_t mask) __attribute__((always_inline)) {
        bool any = false;
        for (; mask; mask &= mask - 1) {
            const int i = std::countr_zero(mask);
            if (test_blocks<false, false, true>(rays[i], tr[i], first_block, count, rays[i].tmax, hits[i])) {
                sr.tmax_scaled[i] = rays[i].tmax * kRobustFarScale;
                any = true;
            }
        }
        return any;
    };

    if (wide8_.root.is_leaf()) {
        leaf(wide8_.root.index, wide8_.root.count, p.active);
    } else {
        struct Entry {
            uint32_t index;   ///< node offset (BvhWide::node_at), or a leaf's first block
            uint32_t count;   ///< a leaf's slot count; 0: inner node
            uint32_t parent;  ///< a leaf's parent node offset + its lane there
            float t_entry;    ///< the frustum's entry distance: at most any ray's
        };
        Entry stack[7 * kBvhMaxDepth + 4];
        int top = 0;
        // As in traverse_wide: no root box test, nodes[0] tests the root's children.
        Entry cur{0, 0, 0, 0.0f};
        for (;;) {
            if (cur.count) {
                const uint32_t mask =
                    rays_in_box(sr, wide8_.node_at(cur.parent & ~7u), int(cur.parent & 7)) & p.active;
                if (mask && leaf(cur.index, cur.count, mask)) reach = max16(sr.tmax_scaled);
            } else {
                const Bvh8Node& n = wide8_.node_at(cur.index);
                const char* base = reinterpret_cast<const char*>(&n);
                __m256 t0 = t_lo, t1 = _mm256_set1_ps(kInfinity);
                for (int a = 0; a < 3; ++a) {
                    t0 = _mm256_max_ps(frustum_plane<true>(base, fa[a]), t0);
                    t1 = _mm256_min_ps(frustum_plane<false>(base, fa[a]), t1);
                }
                // Conservative: t0 is at most, t1 * scale at least, every ray's own value.
                const __m256 far_t =
                    _mm256_min_ps(_mm256_mul_ps(t1, _mm256_set1_ps(kRobustFarScale)), _mm256_set1_ps(reach));
                int any = _mm256_movemask_ps(_mm256_cmp_ps(t0, far_t, _CMP_LE_OQ));
                if (any) {
                    alignas(32) float order[8];
                    _mm256_store_ps(order, t0);
                    const uint32_t parent = cur.index;  // a node offset: its low 8 bits are 0
                    int c = std::countr_zero(unsigned(any));
                    any &= any - 1;
                    cur = Entry{n.child_index(c), n.leaf_count(c), parent + uint32_t(c), order[c]};
                    if (!any) continue;
                    // The others into the stack top, farthest deepest; the nearest becomes `cur`.
                    const int base_top = top;
                    do {
                        c = std::countr_zero(unsigned(any));
                        any &= any - 1;
                        Entry in{n.child_index(c), n.leaf_count(c), parent + uint32_t(c), order[c]};
                        if (in.t_entry < cur.t_entry) std::swap(in, cur);
                        int k = top++;
                        while (k > base_top && stack[k - 1].t_entry < in.t_entry) {
                            stack[k] = stack[k - 1];
                            --k;
                        }
                        stack[k] = in;
                    } while (any);
                    continue;
                }
            }
            // Pop the nearest entry that some ray can still reach.
            for (;;) {
                if (top == 0) goto done;
                cur = stack[--top];
                if (cur.t_entry <= reach) break;
            }
        }
    }
done:
    for (uint32_t m = p.active; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        if (!hits[i].hit()) continue;
        out.t[i] = hits[i].t, out.prim[i] = hits[i].prim, out.u[i] = hits[i].u, out.v[i] = hits[i].v;
    }
}

}  // namespace sahara
