// The spatial-split builder (BvhBuilder::sbvh): structure (every triangle referenced,
// never twice in a leaf, references within the budget, leaf boxes covering every
// triangle) and agreement with brute force on nearest hits and occlusion.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <omp.h>

#include "accel/bvh_sbvh.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"
#include "scene/scene.h"

using namespace sahara;
using namespace sahara::test;

namespace {

void add_quad(TriangleMesh& m, const Vec3& o, const Vec3& u, const Vec3& v) {
    const auto base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {o, o + u, o + u + v, o + v});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// A room: six walls of two triangles each (big, overlapping every other box), a few
/// hundred small random boxes inside, and `planks` long thin planks across the room.
TriangleMesh make_room(uint32_t seed, int planks = 100) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    TriangleMesh m;
    m.name = "room";
    const Vec3 size(10.0f, 4.0f, 8.0f);
    add_quad(m, Vec3(0.0f), Vec3(size.x, 0, 0), Vec3(0, 0, size.z));          // floor
    add_quad(m, Vec3(0, size.y, 0), Vec3(0, 0, size.z), Vec3(size.x, 0, 0));  // ceiling
    add_quad(m, Vec3(0.0f), Vec3(0, size.y, 0), Vec3(size.x, 0, 0));          // walls
    add_quad(m, Vec3(0, 0, size.z), Vec3(size.x, 0, 0), Vec3(0, size.y, 0));
    add_quad(m, Vec3(0.0f), Vec3(0, 0, size.z), Vec3(0, size.y, 0));
    add_quad(m, Vec3(size.x, 0, 0), Vec3(0, size.y, 0), Vec3(0, 0, size.z));
    for (int i = 0; i < 300; ++i) {  // small boxes (furniture, clutter)
        const Vec3 c(u(rng) * size.x, u(rng) * size.y, u(rng) * size.z);
        const float s = 0.05f + 0.3f * u(rng);
        const Vec3 o = c - Vec3(s * 0.5f);
        add_quad(m, o, Vec3(s, 0, 0), Vec3(0, s, 0));
        add_quad(m, o, Vec3(0, s, 0), Vec3(0, 0, s));
        add_quad(m, o, Vec3(0, 0, s), Vec3(s, 0, 0));
    }
    for (int i = 0; i < planks; ++i) {  // long thin diagonal planks
        const Vec3 a(u(rng) * size.x, u(rng) * size.y, u(rng) * size.z);
        const Vec3 b(u(rng) * size.x, u(rng) * size.y, u(rng) * size.z);
        add_quad(m, a, b - a, Vec3(0.0f, 0.01f, 0.0f));
    }
    return m;
}

struct TriangleInput {
    std::vector<Bounds3> boxes;
    std::vector<Vec3> centers;
};

TriangleInput boxes_of(const TriangleMesh& m) {
    TriangleInput in;
    in.boxes = triangle_boxes(m);
    for (const Bounds3& b : in.boxes) in.centers.push_back(b.center());
    return in;
}

/// Structural check of a spatial-split tree; "" when fine. Leaf boxes must cover each
/// triangle: every sample point of a triangle lies in some leaf box that references it.
std::string check_split_tree(const Bvh& bvh, const TriangleMesh& m, float budget) {
    const size_t n = m.triangle_count();
    if (bvh.prim_indices.size() > size_t(double(n) * double(budget))) return "over the reference budget";
    std::vector<std::vector<Bounds3>> leaf_boxes(n);
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const BvhNode& node = bvh.nodes[stack.back()];
        stack.pop_back();
        if (!node.is_leaf()) {
            for (uint32_t c = node.index; c < node.index + 2; ++c) {
                if (!node.box().contains(bvh.nodes[c].box())) return "child outside its parent";
                stack.push_back(c);
            }
            continue;
        }
        std::vector<uint32_t> prims(bvh.prim_indices.begin() + node.index,
                                    bvh.prim_indices.begin() + node.index + node.count);
        std::sort(prims.begin(), prims.end());
        if (std::adjacent_find(prims.begin(), prims.end()) != prims.end())
            return "a triangle twice in one leaf";
        for (const uint32_t p : prims) leaf_boxes[p].push_back(node.box());
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t t = 0; t < n; ++t) {
        if (leaf_boxes[t].empty()) return "triangle " + std::to_string(t) + " in no leaf";
        const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                   c = m.positions[m.indices[3 * t + 2]];
        for (int k = 0; k < 40; ++k) {
            double s = double(u(rng)), r = double(u(rng));
            if (k < 3) s = k == 1 ? 1.0 : 0.0, r = k == 2 ? 1.0 : 0.0;  // the corners
            if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
            // In double: a float sample can land an ulp outside the triangle's own box.
            double p[3];
            for (int i = 0; i < 3; ++i)
                p[i] = double(a[i]) + (double(b[i]) - double(a[i])) * s + (double(c[i]) - double(a[i])) * r;
            const auto inside = [&p](const Bounds3& box) {
                for (int i = 0; i < 3; ++i)
                    if (p[i] < double(box.lo[i]) || p[i] > double(box.hi[i])) return false;
                return true;
            };
            const bool covered = std::any_of(leaf_boxes[t].begin(), leaf_boxes[t].end(), inside);
            if (!covered) return "a point of triangle " + std::to_string(t) + " outside its leaves";
        }
    }
    return "";
}

int disagreements(const Accelerator& acc, const std::vector<Ray>& rays) {
    int bad = 0;
    for (const Ray& ray : rays) {
        Ray a = ray, b = ray;
        Hit ha, hb;
        const bool fa = acc.intersect(a, ha), fb = acc.intersect_brute_force(b, hb);
        if (fa != fb || acc.occluded(ray) != fb)
            ++bad;
        else if (fa && (ha.t != hb.t || (ha.prim != hb.prim && ha.t != hb.t)))
            ++bad;
    }
    return bad;
}

std::vector<TriangleMesh> split_test_meshes() {
    return {make_room(1), make_room(2), make_slivers(2000), make_icosphere(3), make_degenerate_mesh()};
}

}  // namespace

TEST_CASE("clip_triangle_to_slab bounds the part of a triangle between two planes") {
    const Vec3 v[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const Bounds3 mid = clip_triangle_to_slab(v, 0, 1.0f, 2.0f);
    CHECK(mid.lo.x == 1.0f);
    CHECK(mid.hi.x == 2.0f);
    CHECK(mid.lo.y <= 0.0f);
    CHECK(mid.hi.y >= 3.0f);
    CHECK(mid.hi.y < 3.001f);
    CHECK(clip_triangle_to_slab(v, 0, 5.0f, 6.0f).empty());
    const Bounds3 all = clip_triangle_to_slab(v, 1, -kInfinity, kInfinity);
    CHECK(all.contains(Bounds3{{0, 0, 0}, {4, 4, 0}}));
}

TEST_CASE("sbvh references every triangle within the budget and covers it with leaf boxes") {
    for (const TriangleMesh& m : split_test_meshes()) {
        for (const float budget : {1.0f, 1.3f, 2.0f}) {
            INFO(m.name, " budget ", budget);
            const TriangleInput in = boxes_of(m);
            BvhBuildParams params;
            params.sbvh_reference_budget = budget;
            params.leaf_block_size = 4;
            const Bvh bvh =
                build_bvh({in.boxes, in.centers, m.positions, m.indices}, BvhBuilder::sbvh, params);
            CHECK(check_split_tree(bvh, m, budget) == "");
            if (budget == 1.0f) CHECK(bvh.prim_indices.size() == m.triangle_count());
        }
    }
    // The room's walls span every box: the builder must actually split there.
    const TriangleMesh room = make_room(1);
    const TriangleInput in = boxes_of(room);
    const Bvh bvh = build_bvh({in.boxes, in.centers, room.positions, room.indices}, BvhBuilder::sbvh);
    CHECK(bvh.prim_indices.size() > room.triangle_count());
}

TEST_CASE("sbvh trees agree with brute force on nearest hits and occlusion") {
    for (const TriangleMesh& m : split_test_meshes()) {
        const Scene scene = scene_from_mesh(m);
        for (const BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs}) {
            AcceleratorOptions opt;
            opt.builder = BvhBuilder::sbvh;
            opt.layout = layout;
            const Accelerator acc(scene, opt);
            const std::vector<Ray> rays = make_random_rays(mesh_bounds(m), 20000 / kSanitizerDivisor, 11);
            INFO(m.name, " ", bvh_layout_name(layout));
            CHECK(disagreements(acc, rays) == 0);
        }
    }
}

TEST_CASE("sbvh builds the same tree at 1 to 3 threads with contiguous slots under every node") {
    // Small task threshold and a tight budget: subtrees finish in a different order at
    // every run, and the extra references run out on the way down.
    const TriangleMesh room = make_room(4, 600);
    const TriangleInput in = boxes_of(room);
    BvhBuildParams params;
    params.parallel_threshold = 32;
    params.sbvh_reference_budget = 1.1f;
    const int saved = omp_get_max_threads();
    std::vector<Bvh> trees;
    for (int run = 0; run < 6; ++run) {
        omp_set_num_threads(1 + run % 3);
        trees.push_back(
            build_bvh({in.boxes, in.centers, room.positions, room.indices}, BvhBuilder::sbvh, params));
    }
    omp_set_num_threads(saved);
    const Bvh& first = trees[0];
    REQUIRE(first.prim_indices.size() > room.triangle_count());
    CHECK(check_split_tree(first, room, 1.1f) == "");
    // Each subtree's slots are one range: the wide collapse merges only such leaves.
    std::vector<std::pair<uint32_t, uint32_t>> range(first.nodes.size());  // first slot, count
    const auto slots_of = [&](auto&& self, uint32_t id) -> std::pair<uint32_t, uint32_t> {
        const BvhNode& node = first.nodes[id];
        if (node.is_leaf()) return {node.index, node.count};
        const auto l = self(self, node.index), r = self(self, node.index + 1);
        if (l.first == ~0u || r.first != l.first + l.second) return {~0u, 0};
        return {l.first, l.second + r.second};
    };
    CHECK(slots_of(slots_of, 0) == std::pair<uint32_t, uint32_t>{0, uint32_t(first.prim_indices.size())});
    for (size_t t = 1; t < trees.size(); ++t) {
        INFO("run ", t);
        CHECK(trees[t].prim_indices == first.prim_indices);
        REQUIRE(trees[t].nodes.size() == first.nodes.size());
        size_t differ = 0;
        for (size_t i = 0; i < first.nodes.size(); ++i)
            differ += std::memcmp(&trees[t].nodes[i], &first.nodes[i], sizeof(BvhNode)) != 0;
        CHECK(differ == 0);
    }
}

TEST_CASE("the automatic builder picks reinsert only for long renders of scenes with huge triangles") {
    // Without planks: the walls alone hold most of the box area.
    const TriangleMesh room = make_room(1, 0), sphere = make_icosphere(4);
    const double room_share = largest_box_area_share(boxes_of(room).boxes);
    const double sphere_share = largest_box_area_share(boxes_of(sphere).boxes);
    CHECK(room_share >= kAutoMinLargestShare);
    CHECK(sphere_share < 0.1);
    const auto pick = [](const TriangleMesh& m, double share, double rays) {
        return choose_bvh_builder(BvhWorkload{m.triangle_count(), rays, share});
    };
    CHECK(pick(room, room_share, 1e9) == BvhBuilder::reinsert);
    CHECK(pick(room, room_share, 0.0) == BvhBuilder::binned);  // unknown ray count
    CHECK(pick(room, room_share, 1e3) == BvhBuilder::binned);  // a short render
    CHECK(pick(sphere, sphere_share, 1e9) == BvhBuilder::binned);
    CHECK(choose_bvh_builder(BvhWorkload{12, 1e9, 1.0}) == BvhBuilder::binned);  // too small to matter
    // The accelerator resolves "auto" and reports what it built.
    const Scene scene = scene_from_mesh(room);
    AcceleratorOptions opt;
    opt.builder = BvhBuilder::automatic;
    opt.expected_rays = 1e9;
    CHECK(Accelerator(scene, opt).builder() == BvhBuilder::reinsert);
    opt.expected_rays = 0;
    CHECK(Accelerator(scene, opt).builder() == BvhBuilder::binned);
}

TEST_CASE("largest_box_area_share with a threshold settles a mesh without the selection") {
    const TriangleMesh sphere = make_icosphere(4), room = make_room(1, 0);
    const std::vector<Bounds3> sphere_boxes = boxes_of(sphere).boxes, room_boxes = boxes_of(room).boxes;
    // Even triangles: the largest one bounds the share below the threshold, and the bound
    // is what comes back (never below the share).
    const double sphere_share = largest_box_area_share(sphere_boxes);
    const double sphere_bound = largest_box_area_share(sphere_boxes, kAutoMinLargestShare);
    CHECK(sphere_bound < kAutoMinLargestShare);
    CHECK(sphere_bound > sphere_share);
    // A room: no bound below the threshold exists, so the share itself.
    CHECK(largest_box_area_share(room_boxes, kAutoMinLargestShare) == largest_box_area_share(room_boxes));
    // One box of 100 times the others' area among 200 (the top 1% is 2 boxes): the bound
    // 200 / 299 is above the threshold but the share 101 / 299 is not; the share it is.
    std::vector<Bounds3> boxes(200, Bounds3{{0, 0, 0}, {1, 1, 1}});
    boxes[57] = Bounds3{{0, 0, 0}, {10, 10, 10}};
    const double share = largest_box_area_share(boxes, kAutoMinLargestShare);
    CHECK(share == largest_box_area_share(boxes));
    CHECK(share == doctest::Approx(101.0 / 299.0));
}

TEST_CASE("largest_box_area_share is the same at 1 to 3 threads") {
    // Areas over twelve orders of magnitude: their double sum rounds, so a sum whose
    // order followed the thread count would differ in the last bits.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> exponent(-3.0f, 3.0f);
    std::vector<Bounds3> boxes(100000);
    for (Bounds3& b : boxes) {
        const float side = std::pow(10.0f, exponent(rng));
        b = Bounds3{{0, 0, 0}, {side, side * 0.5f, side * 0.25f}};
    }
    const int saved = omp_get_max_threads();
    std::vector<double> shares, bounds;
    for (int threads = 1; threads <= 3; ++threads) {
        omp_set_num_threads(threads);
        shares.push_back(largest_box_area_share(boxes));
        bounds.push_back(largest_box_area_share(boxes, 1.0));
    }
    omp_set_num_threads(saved);
    for (int t = 1; t < 3; ++t) {
        CHECK(std::memcmp(&shares[t], &shares[0], sizeof(double)) == 0);
        CHECK(std::memcmp(&bounds[t], &bounds[0], sizeof(double)) == 0);
    }
    CHECK(bounds[0] >= shares[0]);
}

TEST_CASE("automatic node pairing leaves out interiors and trees that fit in the cache") {
    CHECK(looks_like_interior(1000, kAutoMinLargestShare));
    CHECK_FALSE(looks_like_interior(999, 1.0));  // too small to matter
    CHECK_FALSE(looks_like_interior(100000, 0.9 * kAutoMinLargestShare));
    CHECK(automatic_node_pairing(2u << 20, 1u << 20, false));
    CHECK_FALSE(automatic_node_pairing(2u << 20, 1u << 20, true));   // an interior
    CHECK_FALSE(automatic_node_pairing(1u << 20, 1u << 20, false));  // fits in the cache
    // A room's tree never pairs automatically, whatever the cache; asked for, it does.
    const TriangleMesh room = make_room(3, 0);  // without planks: the walls hold most box area
    REQUIRE(looks_like_interior(room.triangle_count(), largest_box_area_share(boxes_of(room).boxes)));
    const Scene scene = scene_from_mesh(room);
    AcceleratorOptions opt;
    CHECK_FALSE(Accelerator(scene, opt).pairs_nodes());
    opt.node_pairing = NodePairing::always;
    CHECK(Accelerator(scene, opt).pairs_nodes());
}
