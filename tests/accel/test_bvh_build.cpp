// The binned builder's set-up shortcuts (bins cleared only where a small range falls,
// non-empty bins found by mask) and the memory bound of the default acceleration structure.
#include <doctest/doctest.h>

#include <vector>

#include "accel/bvh.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"
#include "scene/scene.h"

namespace sahara {

using namespace test;

namespace {

std::vector<Bounds3> boxes_of(const TriangleMesh& m) {
    std::vector<Bounds3> boxes;
    for (size_t i = 0; i < m.triangle_count(); ++i) {
        Bounds3 b;
        for (int k = 0; k < 3; ++k) b.extend(m.positions[m.indices[3 * i + size_t(k)]]);
        boxes.push_back(b);
    }
    return boxes;
}

bool same_box(const Bounds3& a, const Bounds3& b) {
    for (int k = 0; k < 3; ++k)
        if (a.lo[k] != b.lo[k] || a.hi[k] != b.hi[k]) return false;
    return true;
}

/// The union of everything below `node`; counts the nodes whose box is not exactly that union.
Bounds3 union_below(const Bvh& bvh, std::span<const Bounds3> prims, uint32_t node, int& loose) {
    const BvhNode& n = bvh.nodes[node];
    Bounds3 u;
    if (n.is_leaf()) {
        for (uint32_t s = n.index; s < n.index + n.count; ++s) u.extend(prims[bvh.prim_indices[s]]);
    } else {
        u.extend(union_below(bvh, prims, n.index, loose));
        u.extend(union_below(bvh, prims, n.index + 1, loose));
    }
    if (!same_box(u, n.box())) ++loose;
    return u;
}

}  // namespace

TEST_CASE("binned build: every node's box is exactly the union of what it holds") {
    // Bins that a small range does not touch keep the boxes of earlier nodes; a box read
    // from such a bin would make a node larger than its contents, which validate_bvh allows.
    const std::vector<TriangleMesh> meshes = {make_icosphere(4), make_slivers(3000), make_tiny_grid(40),
                                              make_degenerate_mesh()};
    for (const TriangleMesh& m : meshes) {
        for (uint32_t bins : {4u, 16u, 64u}) {
            BvhBuildParams p;
            p.bin_count = bins;
            p.leaf_block_size = 4;
            const std::vector<Bounds3> boxes = boxes_of(m);
            std::vector<Vec3> centers;
            for (const Bounds3& b : boxes) centers.push_back(b.center());
            const Bvh bvh = build_bvh({boxes, centers}, BvhBuilder::binned, p);
            INFO(m.name, " bins ", bins);
            REQUIRE(bvh.nodes.size() > 1);
            int loose = 0;
            union_below(bvh, boxes, 0, loose);
            CHECK(loose == 0);
        }
    }
}

TEST_CASE("the default acceleration structure keeps at most 64 bytes per triangle") {
    // Tree plus leaf triangle blocks (what Accelerator::bytes counts for the wide layout).
    for (const TriangleMesh& m : {make_icosphere(5), make_slivers(20000), make_scan_mesh(60, 90, 4, 3)}) {
        const Scene scene = scene_from_mesh(m);
        const Accelerator acc(scene);
        INFO(m.name, " ", acc.bytes(), " bytes for ", acc.primitive_count(), " triangles");
        REQUIRE(acc.primitive_count() == m.triangle_count());
        CHECK(double(acc.bytes()) / double(acc.primitive_count()) <= 64.0);
    }
}

}  // namespace sahara
