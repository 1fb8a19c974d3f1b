// 16-ray packets over the wide8 tree without a 16-lane register file (AVX2):
// the packet shares one traversal (stack, child ordering, node fetches), and
// each ray tests a node's eight child boxes in one AVX step and a leaf's
// triangles eight at a time, i.e. with the single-ray box and leaf code. The
// wide-node variant of packet tracing (Wald, Benthin and Boulos, "Getting Rid
// of Packets", 2008) with SIMD across children instead of across rays: for
// 8 children the per-ray test is as wide as the node, so nothing is lost to
// rays that miss, and what the packet saves is the traversal bookkeeping.
//
// Hits equal intersect()'s: the same box and leaf tests per ray; a ray visits
// every subtree its own traversal would (and possibly more), so only which of
// two primitives at exactly the same distance wins may differ.
#include <immintrin.h>

#include <bit>

#include "accel/accelerator.h"
#include "accel/leaf_blocks.inl"
#include "accel/packet.h"

namespace sahara {

__attribute__((target("avx2"))) void Accelerator::trace_packet8_avx2(const RayPacket& p,
                                                                     HitPacket& out) const {
    // Per-lane single-ray constants; inactive lanes are never read.
    Ray rays[kPacketSize];
    TriangleRay tr[kPacketSize];
    Bvh8RayAvx box[kPacketSize];
    Hit hits[kPacketSize];
    alignas(32) float tmax_scaled[kPacketSize] = {};  // tmax * kRobustFarScale, for the pop test
    for (uint32_t m = p.active; m; m &= m - 1) {
        const int i = std::countr_zero(m);
        rays[i] = p.ray(i);
        tr[i] = TriangleRay(rays[i]);
        box[i] = Bvh8RayAvx(BvhRay(rays[i]));
        tmax_scaled[i] = rays[i].tmax * kRobustFarScale;
    }
    auto leaf = [&](uint32_t first, uint32_t count, uint32_t mask) __attribute__((always_inline)) {
        for (; mask; mask &= mask - 1) {
            const int i = std::countr_zero(mask);
            if (test_blocks<false, false, true>(rays[i], tr[i], first, count, rays[i].tmax, hits[i]))
                tmax_scaled[i] = rays[i].tmax * kRobustFarScale;
        }
    };
    if (wide8_.root.is_leaf()) {
        leaf(wide8_.root.index, wide8_.root.count, p.active);
    } else {
        struct Entry {
            uint32_t index, count;  ///< node, or first block and slot count of a leaf
            uint32_t mask;          ///< rays that entered its box
            float t_entry;          ///< the smallest entry distance of those rays
        };
        Entry stack[7 * kBvhMaxDepth + 4];
        int top = 0;
        // As in traverse_wide: no root box test, nodes[0] tests the root's children.
        Entry cur{0, 0, p.active, 0.0f};
        for (;;) {
            if (cur.count) {
                leaf(cur.index, cur.count, cur.mask);
            } else {
                const Bvh8Node& n = wide8_.nodes[cur.index];
                uint32_t child_rays[8] = {};
                __m256 t_min = _mm256_set1_ps(kInfinity);
                int any = 0;
                for (uint32_t m = cur.mask; m; m &= m - 1) {
                    const int i = std::countr_zero(m);
                    alignas(32) float t[8];
                    int hit = intersect_bvh8_avx(n, box[i], rays[i].tmin, rays[i].tmax, t);
                    if (!hit) continue;
                    any |= hit;
                    // Children missed by this ray may hold NaN or large t: min ignores a NaN
                    // first operand, and a too-small order only costs time, never a hit.
                    t_min = _mm256_min_ps(_mm256_load_ps(t), t_min);
                    for (; hit; hit &= hit - 1) child_rays[std::countr_zero(unsigned(hit))] |= 1u << i;
                }
                if (any) {
                    alignas(32) float order[8];
                    _mm256_store_ps(order, t_min);
                    int c = std::countr_zero(unsigned(any));
                    any &= any - 1;
                    cur = Entry{n.child[c], n.count[c], child_rays[c], order[c]};
                    if (!any) continue;
                    // The others into the stack top, farthest deepest; the nearest becomes `cur`.
                    const int base = top;
                    do {
                        c = std::countr_zero(unsigned(any));
                        any &= any - 1;
                        Entry in{n.child[c], n.count[c], child_rays[c], order[c]};
                        if (in.t_entry < cur.t_entry) std::swap(in, cur);
                        int k = top++;
                        while (k > base && stack[k - 1].t_entry < in.t_entry) {
                            stack[k] = stack[k - 1];
                            --k;
                        }
                        stack[k] = in;
                    } while (any);
                    continue;
                }
            }
            // Pop the nearest entry some of whose rays can still find a closer hit there.
            for (;;) {
                if (top == 0) goto done;
                cur = stack[--top];
                const __m256 t = _mm256_set1_ps(cur.t_entry);
                const uint32_t reach =
                    uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(t, _mm256_load_ps(tmax_scaled), _CMP_LE_OQ))) |
                    uint32_t(
                        _mm256_movemask_ps(_mm256_cmp_ps(t, _mm256_load_ps(tmax_scaled + 8), _CMP_LE_OQ)))
                        << 8;
                cur.mask &= reach;
                if (cur.mask) break;
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
