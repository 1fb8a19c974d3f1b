// The binned builder's set-up shortcuts (bins cleared only where a small range falls,
// non-empty bins found by mask) and the memory bound of the default acceleration structure.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_binned.h"
#include "accel/bvh_bins.h"
#include "accel/bvh_stats.h"
#include "accel/simd_path.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"
#include "scene/scene.h"

namespace sahara {

using namespace test;

namespace {

double blocked_leaf(uint32_t n, const BvhBuildParams& p) {
    return double((n + p.leaf_block_size - 1) / p.leaf_block_size * p.leaf_block_size);
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

/// Reference for a leaf of `count` primitives from slot `first`: the cheapest split over
/// the centroid bins per axis the builder uses for `count` primitives (its rule, recomputed
/// here in plain code), as
/// traversal + intersection * sum(child area * blocked child count); +inf if none.
double cheapest_binned_split(const Bvh& bvh, std::span<const Bounds3> prims, uint32_t first, uint32_t count,
                             const BvhBuildParams& p) {
    Bounds3 box, centroids;
    for (uint32_t s = first; s < first + count; ++s) {
        box.extend(prims[bvh.prim_indices[s]]);
        centroids.extend(prims[bvh.prim_indices[s]].center());
    }
    auto blocked = [&](uint32_t n) {
        return double((n + p.leaf_block_size - 1) / p.leaf_block_size * p.leaf_block_size);
    };
    const uint32_t bins = binned_bin_count(count, p.bin_count);
    double best = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
        const float extent = centroids.hi[axis] - centroids.lo[axis];
        if (!(extent > 0.0f)) continue;
        for (uint32_t pos = 1; pos < bins; ++pos) {
            Bounds3 left, right;
            uint32_t nl = 0, nr = 0;
            for (uint32_t s = first; s < first + count; ++s) {
                const Bounds3& b = prims[bvh.prim_indices[s]];
                const int bin = std::clamp(
                    int((b.center()[axis] - centroids.lo[axis]) * (float(bins) / extent)), 0, int(bins) - 1);
                if (uint32_t(bin) < pos)
                    left.extend(b), ++nl;
                else
                    right.extend(b), ++nr;
            }
            if (nl == 0 || nr == 0) continue;
            best = std::min(best,
                            double(p.traversal_cost) * double(box.surface_area()) +
                                double(p.intersection_cost) * (double(left.surface_area()) * blocked(nl) +
                                                               double(right.surface_area()) * blocked(nr)));
        }
    }
    return best;
}

/// Adds the twelve triangles of the box [lo, hi].
void add_box(TriangleMesh& m, const Vec3& lo, const Vec3& hi) {
    const auto base = uint32_t(m.positions.size());
    for (int i = 0; i < 8; ++i)
        m.positions.push_back(Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
    const uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces)
        m.indices.insert(m.indices.end(),
                         {base + f[0], base + f[1], base + f[2], base + f[0], base + f[2], base + f[3]});
}

/// An open-plan office: floor and ceiling slabs with a thickness reaching under the
/// walls, four walls (boxes) and a grid of ceiling light panels.
TriangleMesh make_slab_office() {
    TriangleMesh m;
    m.name = "slab office";
    const float length = 30, width = 16, height = 3.2f, t = 0.3f;
    add_box(m, Vec3(-t, -t, -t), Vec3(length + t, width + t, 0));               // floor slab
    add_box(m, Vec3(-t, -t, height), Vec3(length + t, width + t, height + t));  // ceiling slab
    add_box(m, Vec3(0, -t, 0), Vec3(length, 0, height));                        // walls
    add_box(m, Vec3(0, width, 0), Vec3(length, width + t, height));
    add_box(m, Vec3(-t, 0, 0), Vec3(0, width, height));
    add_box(m, Vec3(length, 0, 0), Vec3(length + t, width, height));
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 6; ++j) {  // light panels under the ceiling
            const float x = 1.2f + 2.4f * float(i), y = 1.2f + 2.4f * float(j);
            add_box(m, Vec3(x - 0.6f, y - 0.3f, height - 0.05f), Vec3(x + 0.6f, y + 0.3f, height));
        }
    return m;
}

/// The most primitives in a leaf that holds a primitive whose box has at least `share`
/// of the root box's surface area.
uint32_t largest_leaf_with_large_primitive(const Bvh& bvh, std::span<const Bounds3> prims, float share) {
    const float large = share * bvh.nodes[0].box().surface_area();
    uint32_t most = 0;
    for (const BvhNode& n : bvh.nodes) {
        if (!n.is_leaf() || n.count == 0) continue;
        for (uint32_t s = n.index; s < n.index + n.count; ++s)
            if (prims[bvh.prim_indices[s]].surface_area() >= large) most = std::max(most, n.count);
    }
    return most;
}

}  // namespace

TEST_CASE("binned build: a leaf is never more expensive than its cheapest binned split") {
    // The builder decides many small leaves without binning them, from a lower bound on
    // every split's cost; a wrong bound would leave leaves that splitting makes cheaper.
    for (const TriangleMesh& m : {make_icosphere(4), make_slivers(3000), make_scan_mesh(40, 60, 3, 5)}) {
        BvhBuildParams p;
        p.leaf_block_size = 4;
        p.intersection_cost = 0.5f;  // the wide layout's weights (AcceleratorOptions::build_params)
        const std::vector<Bounds3> boxes = triangle_boxes(m);
        std::vector<Vec3> centers;
        for (const Bounds3& b : boxes) centers.push_back(b.center());
        const Bvh bvh = build_bvh({boxes, centers}, BvhBuilder::binned, p);
        int leaves = 0, too_expensive = 0;
        for (const BvhNode& n : bvh.nodes) {
            if (!n.is_leaf() || n.count < 2 || &n == &bvh.nodes[1]) continue;
            ++leaves;
            const double leaf =
                double(p.intersection_cost) * blocked_leaf(n.count, p) * double(n.box().surface_area());
            if (leaf > cheapest_binned_split(bvh, boxes, n.index, n.count, p) * (1 + 1e-5)) ++too_expensive;
        }
        INFO(m.name, " ", too_expensive, " of ", leaves, " leaves");
        REQUIRE(leaves > 100);
        CHECK(too_expensive == 0);
    }
}

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
            const std::vector<Bounds3> boxes = triangle_boxes(m);
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

TEST_CASE("binned build: the SSE2 and AVX2 binning kernels build the same tree bit for bit") {
    // The AVX2 kernel keeps bin boxes as (lo, -hi); a wrong operand order or sign would
    // change a box's signed zero or a NaN's side, and with it a split or a node's bounds.
    struct Restore {
        ~Restore() { clear_forced_simd_path(); }
    } restore;
    const std::vector<SimdPath> paths = runnable_simd_paths();
    if (paths.size() < 2) MESSAGE("this CPU runs only the SSE2 kernel");
    // Long ranges (two bin sets, parallel chunks above 32,768 primitives) and odd boxes.
    for (const TriangleMesh& m :
         {make_slivers(40000), make_icosphere(4), make_degenerate_mesh(), make_tiny_grid(40)}) {
        const std::vector<Bounds3> boxes = triangle_boxes(m);
        std::vector<Vec3> centers;
        for (const Bounds3& b : boxes) centers.push_back(b.center());
        BvhBuildParams p;
        p.leaf_block_size = 4;
        force_simd_path(SimdPath::sse2);
        const Bvh reference = build_bvh({boxes, centers}, BvhBuilder::binned, p);
        for (SimdPath path : paths) {
            force_simd_path(path);
            const Bvh bvh = build_bvh({boxes, centers}, BvhBuilder::binned, p);
            INFO(m.name, " ", simd_path_name(path));
            REQUIRE(bvh.nodes.size() == reference.nodes.size());
            CHECK(bvh.prim_indices == reference.prim_indices);
            CHECK(std::memcmp(bvh.nodes.data(), reference.nodes.data(), bvh.nodes.size() * sizeof(BvhNode)) ==
                  0);
        }
    }
}

TEST_CASE("binned build: the partition's centroid threshold puts every centroid on its bin's side") {
    // The threshold is searched from the boundary's computed position; one float off
    // would move the centroids on the boundary to the other child.
    std::mt19937 rng(7);
    int checked = 0, wrong = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const float scale = std::ldexp(1.0f, int(rng() % 40) - 20);
        const float lo = (float(rng() % 2001) - 1000.0f) * scale * 0.01f;
        const float extent = float(1 + rng() % 1000) * scale * 0.001f;
        Bounds3 cents{{lo, lo, lo}, {lo + extent, lo + extent * 0.5f, lo + extent * 3.0f}};
        const uint32_t bins = trial % 2 ? 16 : 8;
        const binned::BinMap map(cents, bins);
        // Centroids on the bounds, spread between them, and the floats around each boundary.
        std::vector<binned::PrimRef> refs;
        for (int axis = 0; axis < 3; ++axis) {
            const float a = cents.lo[axis], b = cents.hi[axis];
            std::vector<float> xs = {a, b};
            for (int k = 0; k < 64; ++k) xs.push_back(a + (b - a) * float(rng() % 10001) * 1e-4f);
            for (uint32_t pos = 1; pos < bins; ++pos) {
                float x = a + float(pos) * (b - a) / float(bins);
                for (int k = 0; k < 6; ++k) x = std::nextafter(x, -kInfinity);
                for (int k = 0; k < 12; ++k, x = std::nextafter(x, kInfinity))
                    if (x >= a && x <= b) xs.push_back(x);
            }
            for (float x : xs) {
                binned::PrimRef r{};
                r.c[0] = r.c[1] = r.c[2] = x;
                refs.push_back(r);
            }
        }
        for (int axis = 0; axis < 3; ++axis)
            for (uint32_t pos = 1; pos < bins; ++pos) {
                const binned::SideTest side(map, axis, pos, cents.hi[axis], 1000);
                for (const binned::PrimRef& r : refs) {
                    if (r.c[axis] < cents.lo[axis] || r.c[axis] > cents.hi[axis]) continue;
                    ++checked;
                    wrong += side.left(r) != (map.bin(r, axis) < pos);
                }
            }
    }
    INFO(wrong, " of ", checked);
    REQUIRE(checked > 100000);
    CHECK(wrong == 0);
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

TEST_CASE("reinsertion keeps the slabs of a room out of large leaves") {
    // A slab spanning the room collapsed into one leaf of its twelve triangles makes every
    // ray from inside the room that reaches it test all twelve; reinsertion's collapse
    // counts a leaf holding such a primitive twice (BvhBuildParams::large_leaf_cost_factor).
    const TriangleMesh m = make_slab_office();
    const std::vector<Bounds3> boxes = triangle_boxes(m);
    std::vector<Vec3> centers;
    for (const Bounds3& b : boxes) centers.push_back(b.center());
    const BvhBuildParams params = AcceleratorOptions{}.build_params();
    const float share = params.large_leaf_area_share;
    REQUIRE(share > 0.0f);
    const Bvh bvh = build_bvh({boxes, centers}, BvhBuilder::reinsert, params);
    CHECK(validate_bvh(bvh, boxes) == "");
    const uint32_t with_rule = largest_leaf_with_large_primitive(bvh, boxes, share);
    BvhBuildParams plain = params;
    plain.large_leaf_cost_factor = 1.0f;
    const uint32_t without_rule = largest_leaf_with_large_primitive(
        build_bvh({boxes, centers}, BvhBuilder::reinsert, plain), boxes, share);
    INFO("with the rule ", with_rule, ", without ", without_rule);
    CHECK(with_rule > 0);
    CHECK(with_rule <= 4);
    CHECK(without_rule > 4);  // the rule, not the room, keeps the leaves small
}

}  // namespace sahara
