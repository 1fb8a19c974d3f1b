#include "accel/crossings.h"

#include "accel/bvh_traverse.h"
#include "accel/traverse_wide.h"
#include "geometry/triangle_crossing.h"

namespace sahara {

namespace {

/// Calls on_hit(ShapeHit, prim id) for each crossing; the traversal visits every
/// leaf whose box the ray enters within (tmin, tmax), since no leaf reports a hit.
template <class OnHit>
void for_each_crossing(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                       OnHit&& on_hit) {
    BvhRay box_ray(ray);
    const TriangleRay tr(ray);
    auto test_leaf = [&](uint32_t first, uint32_t count, float) {
        const uint32_t end = first + (count + 3) / 4;
        for (uint32_t b = first; b < end && b < blocks.size(); ++b) {
            const TriangleBlock4& block = blocks[b];
            for (int l = 0; l < 4; ++l) {
                const uint32_t slot = block.slot[l];
                if (slot == TriangleBlock4::kEmptyLane || (slot & TriangleBlock4::kOtherKind)) continue;
                const TriangleVerts tri{{{block.p[0][0][l], block.p[0][1][l], block.p[0][2][l]},
                                         {block.p[1][0][l], block.p[1][1][l], block.p[1][2][l]},
                                         {block.p[2][0][l], block.p[2][1][l], block.p[2][2][l]}}};
                ShapeHit h{};
                if (cross_triangle(tr, tri, ray.tmin, ray.tmax, h)) on_hit(h, slot);
            }
        }
        return false;  // keeps tmax: every leaf the ray enters is visited
    };
    auto defer = [](uint32_t, uint32_t, uint32_t, uint32_t, bool&, float&) { return LeafResult::slow; };
    NoTraversalCounters counters;
    traverse_wide<false>(tree, box_ray, defer, test_leaf, counters);
}

}  // namespace

void collect_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray,
                       std::vector<Hit>& out) {
    for_each_crossing(tree, blocks, ray, [&](const ShapeHit& h, uint32_t prim) {
        out.push_back(Hit{h.t, prim, h.u, h.v});
    });
}

uint32_t count_crossings(const Bvh8& tree, std::span<const TriangleBlock4> blocks, const Ray& ray) {
    uint32_t n = 0;
    for_each_crossing(tree, blocks, ray, [&](const ShapeHit&, uint32_t) { ++n; });
    return n;
}

}  // namespace sahara
