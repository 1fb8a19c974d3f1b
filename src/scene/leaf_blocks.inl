#pragma once
// The leaf tests of Accelerator (definitions of its always-inline member templates:
// triangle blocks and leaf slots), shared by the single-ray traversal
// (trace_wide.inl), the brute-force and pair-layout paths (accelerator.cpp) and the
// wide8 packet traversal (packet_wide8.cpp). Include only from those.
#include <immintrin.h>

#include "scene/accelerator.h"
#include "accel/bvh4_leaf.h"

namespace sahara {

/// The lane of `mask` (not 0) with the smallest t; ties keep the earlier lane.
__attribute__((always_inline)) inline int nearest_lane(int mask, const float* t) {
    int best = __builtin_ctz(unsigned(mask));
    for (int m = mask & (mask - 1); m; m &= m - 1) {
        const int l = __builtin_ctz(unsigned(m));
        if (t[l] < t[best]) best = l;
    }
    return best;
}

template <bool kAnyHit>
__attribute__((always_inline)) inline int Accelerator::keep_block_lanes(const Ray& ray, uint32_t first,
                                                                        int mask, const float* t,
                                                                        const float* u,
                                                                        const float* v) const {
    // Nearest first, so at most the lanes in front of the kept one are alpha-tested.
    while (mask) {
        const int best = kAnyHit ? __builtin_ctz(unsigned(mask)) : nearest_lane(mask, t);
        if (keep_triangle_hit(ray, block_slot(first, best), u[best], v[best])) return 1 << best;
        mask &= ~(1 << best);
    }
    return 0;
}

/// Vertex v of lane l of block b.
inline Vec3 block_vertex(const TriangleBlock4& b, int v, int l) {
    return Vec3(b.p[v][0][l], b.p[v][1][l], b.p[v][2][l]);
}

__attribute__((always_inline)) inline int Accelerator::cull_block_lanes(const Ray& ray,
                                                                        const TriangleBlock4* b0,
                                                                        const TriangleBlock4* b1,
                                                                        int mask) const {
    for (int m = mask; m; m &= m - 1) {
        const int l = __builtin_ctz(unsigned(m));
        const TriangleBlock4& b = l < 4 ? *b0 : *b1;
        if (culls(b.slot[l & 3], ray.dir, block_vertex(b, 0, l & 3), block_vertex(b, 1, l & 3),
                  block_vertex(b, 2, l & 3)))
            mask &= ~(1 << l);
    }
    return mask;
}

/// The common leaf, one or two blocks of triangles, without a call: a leaf with
/// other kinds or more blocks, a lane the SIMD step leaves to the scalar test
/// (redo_scalar_lanes) and every leaf of a scene with cut-outs (the alpha test) are
/// `slow`, answered by test_blocks with nothing changed here.
///
/// A one-block leaf is tested together with the entry the traversal would visit
/// next (`next_first`, `next_count`; count 0: none or an inner node) when that is a
/// one-block leaf of triangles too; `paired` then says so, and the traversal drops
/// that entry. Two blocks take one AVX step (kAvx) where one block takes an SSE
/// step, and the next leaf is often visited anyway.
template <bool kAnyHit, bool kCutouts, bool kAvx>
__attribute__((always_inline)) inline LeafResult Accelerator::test_blocks_fast(
    const Ray& ray, const TriangleRay& tr, uint32_t first, uint32_t count, uint32_t next_first,
    uint32_t next_count, bool& paired, float& tmax, Hit& hit) const {
    if (kCutouts || count > 8) return LeafResult::slow;
    const TriangleBlock4* b0 = &blocks_[first];
    const TriangleBlock4* b1 = b0 + 1;  // the leaf's second block, or the next leaf's block
    bool two = count > 4;
    if (other_lanes(*b0) | (two ? other_lanes(*b1) : 0)) return LeafResult::slow;
    const bool pair = !two && next_count - 1 < 4 && !other_lanes(blocks_[next_first]);  // next_count 1..4
    if (pair) b1 = &blocks_[next_first], two = true;
    alignas(32) float t[8], u[8], v[8];
    int scalar_lanes = 0, mask = 0;
    if (kAvx && two) {
        mask = intersect_triangle_blocks2_avx_simd(tr, b0, b1, ray.tmin, tmax, t, u, v, scalar_lanes);
    } else {
        mask = intersect_triangle_block4_simd(tr, *b0, ray.tmin, tmax, t, u, v, scalar_lanes);
        // Distances of the first block's hits are not yet below tmax here: the
        // nearest of all eight lanes is picked below, as the AVX step does.
        if (two && !scalar_lanes)
            mask |= intersect_triangle_block4_simd(tr, *b1, ray.tmin, tmax, t + 4, u + 4, v + 4, scalar_lanes)
                    << 4;
    }
    if (scalar_lanes) return LeafResult::slow;
    paired = pair;
    if (mask && !one_sided_.empty()) mask = cull_block_lanes(ray, b0, b1, mask);
    if (!mask) return LeafResult::miss;
    if constexpr (!kAnyHit) {
        const int best = nearest_lane(mask, t);
        tmax = t[best];
        hit = Hit{t[best], (best < 4 ? b0 : b1)->slot[best & 3], u[best], v[best]};
    } else {
        hit.prim = uint32_t(((mask & 0xF) ? b0 : b1) - blocks_.data());  // for OcclusionCache
    }
    return LeafResult::hit;
}

/// Tests the leaf blocks [first, first + ceil(count / 4)): triangles four at a
/// time (kAvx: eight, two blocks per step), other kinds through intersect_other;
/// the closest hit lowers `tmax`. Ties keep the earlier lane, as one block at a time would.
template <bool kAnyHit, bool kCutouts, bool kAvx>
__attribute__((always_inline)) inline bool Accelerator::test_blocks(const Ray& ray, const TriangleRay& tr,
                                                                    uint32_t first, uint32_t count,
                                                                    float& tmax, Hit& hit) const {
    bool found = false;
    const uint32_t end = first + (count + 3) / 4;
    for (uint32_t b = first; b < end;) {
        const bool pair = kAvx && b + 1 < end;
        alignas(32) float t[8], u[8], v[8];
        // Lanes of other kinds (not padding); a step with nothing but those (e.g. a
        // full block of spheres) skips the triangle test.
        const int other = other_lanes(blocks_[b]) | (pair ? other_lanes(blocks_[b + 1]) << 4 : 0);
        int mask = 0;
        if (other != (pair ? 0xFF : 0xF)) {
            if constexpr (kAvx)
                mask = pair ? intersect_triangle_blocks2_avx(tr, &blocks_[b], ray.tmin, tmax, t, u, v)
                            : intersect_triangle_block4(tr, blocks_[b], ray.tmin, tmax, t, u, v);
            else
                mask = intersect_triangle_block4(tr, blocks_[b], ray.tmin, tmax, t, u, v);
        }
        if (mask && !one_sided_.empty())
            mask = cull_block_lanes(ray, &blocks_[b], &blocks_[b + (pair ? 1 : 0)], mask);
        if constexpr (kCutouts)
            if (mask) mask = keep_block_lanes<kAnyHit>(ray, b, mask, t, u, v);
        if (mask) {
            if constexpr (kAnyHit) {
                hit.prim = b + ((mask & 0xF) ? 0 : 1);  // the occluder's block, for OcclusionCache
                return true;
            }
            const int best = nearest_lane(mask, t);
            tmax = t[best];
            hit = Hit{t[best], block_slot(b, best), u[best], v[best]};
            found = true;
        }
        for (int m = other; m; m &= m - 1) {
            const uint32_t id =
                others_[block_slot(b, __builtin_ctz(unsigned(m))) & ~TriangleBlock4::kOtherKind];
            if constexpr (kAnyHit) {
                if (occluded_other(ray, id, tmax)) {
                    hit.prim = b + uint32_t(__builtin_ctz(unsigned(m)) >> 2);
                    return true;
                }
            } else if (const std::optional<ShapeHit> h = intersect_other(ray, id, tmax)) {
                tmax = h->t;
                hit = Hit{h->t, id, 0.0f, 0.0f};  // a quadric's part: Scene::interact (Quadric::hit_at)
                found = true;
            }
        }
        b += pair ? 2 : 1;
    }
    return found;
}

/// Tests the primitives in slots [first, first + count); the closest hit lowers `tmax` and is stored in
/// `hit`.
template <bool kAnyHit, bool kCutouts>
__attribute__((always_inline)) inline bool Accelerator::test_slots(const Ray& ray, const TriangleRay& tr,
                                                                   uint32_t first, uint32_t count,
                                                                   float& tmax, Hit& hit) const {
    bool found = false;
    for (uint32_t s = first; s < first + count; ++s) {
        const uint32_t id = slots_[s].id;
        std::optional<ShapeHit> h;
        if (prim_kind(id) == PrimKind::triangle) {
            h = slots_[s].tri.intersect(tr, ray.tmin, tmax);
            const TriangleVerts& v = slots_[s].tri;
            if (h && !one_sided_.empty() && culls(id, ray.dir, v.vertex(0), v.vertex(1), v.vertex(2)))
                continue;
            if constexpr (kCutouts)
                if (h && !keep_triangle_hit(ray, id, h->u, h->v)) continue;
        } else {
            if constexpr (kAnyHit) {
                if (occluded_other(ray, id, tmax)) return true;
                continue;
            }
            h = intersect_other(ray, id, tmax);
        }
        if (!h) continue;
        if constexpr (kAnyHit) return true;
        tmax = h->t;
        hit = Hit{h->t, id, h->u, h->v};
        found = true;
    }
    return found;
}

}  // namespace sahara
