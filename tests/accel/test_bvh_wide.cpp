#include <doctest/doctest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <map>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/accelerator.h"
#include "accel/bvh_stats.h"
#include "accel/simd_path.h"
#include "accel/traverse_wide.h"
#include "io/mesh_triangles.h"
#include "scene/mesh_scene.h"
#include "mesh_fixtures.h"
#include "scene/scene.h"
#include "test_data.h"

using namespace sahara;
using namespace sahara::test;

namespace {

std::vector<TriangleMesh> procedural() {
    return {make_icosphere(3), make_tiny_grid(30), make_slivers(1000), make_degenerate_mesh()};
}

/// Restores automatic SIMD path selection when a test ends.
struct SimdPathGuard {
    ~SimdPathGuard() { force_simd_path(best_simd_path()); }
};

/// The SIMD paths this CPU can run (SSE2 always).
std::vector<SimdPath> runnable_paths() { return runnable_simd_paths(); }

template <int N>
Bounds3 child_box(const BvhWideNode<N>& n, int c) {
    return {{n.lo_x[c], n.lo_y[c], n.lo_z[c]}, {n.hi_x[c], n.hi_y[c], n.hi_z[c]}};
}

bool inside(const Bounds3& inner, const Bounds3& outer) {
    if (inner.lo.x > inner.hi.x) return true;  // empty
    for (int a = 0; a < 3; ++a)
        if (inner.lo[a] < outer.lo[a] || inner.hi[a] > outer.hi[a]) return false;
    return true;
}

/// Marks the primitives of one leaf (first slot or, with leaf blocks, first block; count
/// slots): by slot index, or with leaf blocks by primitive id.
void use_leaf(const Accelerator& acc, uint32_t first, uint32_t count, std::map<uint32_t, int>& uses) {
    if (!layout_has_blocks(acc.layout())) {
        REQUIRE(first + count <= acc.primitive_count());
        for (uint32_t s = 0; s < count; ++s) ++uses[first + s];
        return;
    }
    const auto& blocks = acc.leaf_blocks();
    REQUIRE(first + (count + 3) / 4 <= blocks.size());
    uint32_t lanes = 0;
    for (uint32_t b = first; b < first + (count + 3) / 4; ++b)
        for (uint32_t slot : blocks[b].slot) {
            if (slot == TriangleBlock4::kEmptyLane) continue;
            ++lanes;
            ++uses[acc.lane_prim(slot)];
        }
    CHECK(lanes == count);
}

/// Every slot in exactly one leaf, every node reached once, child boxes inside the parent's box.
template <int N>
void check_wide_valid(const Accelerator& acc, const BvhWide<N>& t) {
    REQUIRE_FALSE(t.empty);
    std::map<uint32_t, int> slot_uses;
    std::vector<int> node_uses(t.nodes.size(), 0);
    if (t.root.is_leaf()) {
        use_leaf(acc, t.root.index, t.root.count, slot_uses);
    } else {
        std::vector<std::pair<uint32_t, Bounds3>> stack{{0u, t.root.box()}};
        while (!stack.empty()) {
            const auto [index, box] = stack.back();
            stack.pop_back();
            REQUIRE(index < t.nodes.size());
            ++node_uses[index];
            const BvhWideNode<N>& n = t.nodes[index];
            int children = 0;
            for (int c = 0; c < N; ++c) {
                if (!n.has_child(c)) {
                    CHECK(n.leaf_count(c) == 0);
                    CHECK(child_box(n, c).lo.x > child_box(n, c).hi.x);
                    continue;
                }
                ++children;
                CHECK(inside(child_box(n, c), box));
                // A reference tells a leaf and its count by itself (wide_leaf_ref).
                if (const uint32_t count = n.leaf_count(c)) {
                    use_leaf(acc, ref_first(n.child[c]), count, slot_uses);
                } else {
                    // Inner children hold node byte offsets (BvhWide::node_at).
                    CHECK(n.child[c] % sizeof(BvhWideNode<N>) == 0);
                    CHECK(&t.node_at(n.child[c]) == &t.nodes[BvhWide<N>::index_of(n.child[c])]);
                    stack.push_back({uint32_t(BvhWide<N>::index_of(n.child[c])), child_box(n, c)});
                }
            }
            CHECK(children >= 2);
        }
    }
    CHECK(slot_uses.size() == acc.primitive_count());
    CHECK(std::all_of(slot_uses.begin(), slot_uses.end(), [](const auto& u) { return u.second == 1; }));
    CHECK(std::all_of(node_uses.begin(), node_uses.end(), [](int u) { return u == 1; }));
}

/// check_wide_valid on the wide8 tree (the pairs layout has none).
void check_wide8_valid(const Accelerator& acc) {
    if (acc.layout() == BvhLayout::wide8)
        check_wide_valid(acc, acc.bvh8());
    else
        CHECK(acc.bvh8().empty);
}

bool same_t(float a, float b) { return std::fabs(a - b) <= 1e-6f * std::max(std::fabs(a), std::fabs(b)); }

/// Rays on which `acc` disagrees with the brute-force loop, for intersect and occluded.
int disagreements(const Accelerator& acc, const std::vector<Ray>& rays) {
    int bad = 0;
    for (const Ray& r0 : rays) {
        Ray a = r0, b = r0;
        Hit ha, hb;
        const bool fa = acc.intersect(a, ha), fb = acc.intersect_brute_force(b, hb);
        if (fa != fb || acc.occluded(r0) != fb)
            ++bad;
        else if (fa && (!same_t(ha.t, hb.t) || (ha.prim != hb.prim && ha.t != hb.t) || a.tmax != ha.t))
            ++bad;
    }
    return bad;
}

/// Both layouts on `paths`: valid trees, brute-force answers; `reinsert` adds the
/// wide8 layout over the reinsertion builder's tree. The wide8 tree is also traced with
/// node pairing for every closest-hit ray (the AVX-512 path).
void check_mesh(const TriangleMesh& mesh, uint32_t seed, bool reinsert,
                const std::vector<SimdPath>& paths = runnable_paths()) {
    const Scene scene = scene_from_mesh(mesh);
    const double budget = 2.5e7 / double(std::max<size_t>(mesh.triangle_count(), 1));
    const int count = int(std::clamp(budget, 1000.0, 20000.0)) / kSanitizerDivisor;
    const std::vector<Ray> rays = make_random_rays(mesh_bounds(mesh), count, seed);
    SimdPathGuard guard;
    struct Config {
        BvhLayout layout;
        BvhBuilder builder;
        NodePairing pairing;
    };
    for (auto [layout, builder, pairing] :
         {Config{BvhLayout::wide8, BvhBuilder::binned, NodePairing::automatic},
          Config{BvhLayout::wide8, BvhBuilder::binned, NodePairing::never},
          Config{BvhLayout::wide8, BvhBuilder::binned, NodePairing::always},
          Config{BvhLayout::pairs, BvhBuilder::binned, NodePairing::automatic},
          Config{BvhLayout::wide8, BvhBuilder::reinsert, NodePairing::always}}) {
        if (builder == BvhBuilder::reinsert && !reinsert) continue;
        AcceleratorOptions opt;
        opt.layout = layout;
        opt.builder = builder;
        opt.node_pairing = pairing;
        const Accelerator acc(scene, opt);
        REQUIRE(acc.layout() == layout);
        if (pairing != NodePairing::automatic) CHECK(acc.pairs_nodes() == (pairing == NodePairing::always));
        check_wide8_valid(acc);
        for (SimdPath path : paths) {
            force_simd_path(path);
            INFO(mesh.name, " layout ", std::string(bvh_layout_name(layout)), " builder ",
                 std::string(bvh_builder_name(builder)), " pairing ", int(pairing), " path ",
                 std::string(simd_path_name(path)), " rays ", rays.size());
            CHECK(active_simd_path() == path);
            CHECK(disagreements(acc, rays) == 0);
        }
    }
}

}  // namespace

// One test case per SIMD path, so that a CPU without AVX2 or AVX-512 shows those paths as skipped.
TEST_CASE("wide BVH is valid and agrees with brute force on procedural meshes, on the SSE2 path") {
    uint32_t seed = 500;
    for (const TriangleMesh& m : procedural()) check_mesh(m, seed++, true, {SimdPath::sse2});
}

TEST_CASE(
    "wide BVH is valid and agrees with brute force on procedural meshes, on the AVX2 path [needs AVX2]" *
    doctest::skip(!cpu_has_avx2())) {
    uint32_t seed = 500;
    for (const TriangleMesh& m : procedural()) check_mesh(m, seed++, true, {SimdPath::avx2});
}

TEST_CASE(
    "wide BVH is valid and agrees with brute force on procedural meshes, on the AVX-512 path "
    "[needs AVX-512]" *
    doctest::skip(!cpu_has_avx512())) {
    uint32_t seed = 500;
    for (const TriangleMesh& m : procedural()) check_mesh(m, seed++, true, {SimdPath::avx512});
}

TEST_CASE("wide BVH is valid and agrees with brute force on real and scan-like meshes, on every SIMD path") {
    uint32_t seed = 600;
    // (The reinsertion tree on these meshes is checked against brute force in test_bvh.cpp.)
    for (const TriangleMesh& m : realistic_meshes()) check_mesh(m, seed++, false);
}

TEST_CASE("node pairing on a deep, lopsided tree agrees with brute force") {
    // Triangles at geometrically growing distances along x, each also scaled up: the SAH
    // splits off one or a few at a time, so the tree runs as deep as the builder lets it,
    // and rays along the axis pass through every level with pending siblings on the stack.
    TriangleMesh m;
    m.name = "comb";
    for (int i = 0; i < 3000; ++i) {
        const float x = std::pow(1.01f, float(i)), s = 0.3f * x;
        const auto base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {Vec3(x, -s, -s), Vec3(x, s, -s), Vec3(x, 0.0f, s)});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    const Scene scene = scene_from_mesh(m);
    AcceleratorOptions opt;
    opt.node_pairing = NodePairing::always;
    const Accelerator acc(scene, opt);
    CHECK(acc.pairs_nodes());
    int depth = 0;  // of the wide tree
    for (std::vector<std::pair<uint32_t, int>> pending{{0u, 1}}; !pending.empty();) {
        const auto [offset, d] = pending.back();
        pending.pop_back();
        depth = std::max(depth, d);
        const Bvh8Node& n = acc.bvh8().node_at(offset);
        for (int c = 0; c < 8; ++c)
            if (n.has_child(c) && n.leaf_count(c) == 0) pending.push_back({n.child[c], d + 1});
    }
    CHECK(depth >= 8);
    MESSAGE("wide tree depth " << depth);
    std::vector<Ray> rays = make_random_rays(acc.bounds(), 4000 / kSanitizerDivisor, 71);
    for (int i = 0; i < 2000 / kSanitizerDivisor; ++i)  // along the comb, from both ends
        rays.push_back(Ray{Vec3(i % 2 ? -1.0f : 1e13f, 0.01f * float(i % 7), 0.01f * float(i % 5)),
                           Vec3(i % 2 ? 1.0f : -1.0f, 1e-3f * float(i % 3), 0.0f)});
    SimdPathGuard guard;
    for (SimdPath path : runnable_paths()) {
        force_simd_path(path);
        INFO(std::string(simd_path_name(path)));
        CHECK(disagreements(acc, rays) == 0);
    }
}

TEST_CASE("wide8 and pair layouts give the same hits") {
    const TriangleMesh m = make_icosphere(4);  // random rays hit it often, even the few under ASan
    const Scene scene = scene_from_mesh(m);
    AcceleratorOptions wide, pairs;
    pairs.layout = BvhLayout::pairs;
    const Accelerator a(scene, wide), b(scene, pairs);
    CHECK(b.layout() == BvhLayout::pairs);
    CHECK(b.bvh8().empty);
    int bad = 0, hits = 0;
    for (const Ray& r0 : make_random_rays(mesh_bounds(m), 20000 / kSanitizerDivisor, 77)) {
        Ray ra = r0, rb = r0;
        Hit ha, hb;
        const bool fa = a.intersect(ra, ha), fb = b.intersect(rb, hb);
        hits += fa;
        if (fa != fb || (fa && ha.t != hb.t) || a.occluded(r0) != b.occluded(r0)) ++bad;
        // The wide8 brute force reads the leaf blocks, the pair one the scene's triangles.
        Ray ba = r0, bb = r0;
        const bool ga = a.intersect_brute_force(ba, ha), gb = b.intersect_brute_force(bb, hb);
        if (ga != gb || (ga && ha.t != hb.t)) ++bad;
    }
    CHECK(bad == 0);
    CHECK(hits > 0);
}

TEST_CASE("wide BVH: mixed primitives, counted traversal and layout names") {
    Scene scene = scene_from_mesh(make_icosphere(2, 0.5f));
    scene.spheres.push_back(Sphere{Vec3(2.0f, 0.0f, 0.0f), 0.4f});
    scene.boxes.push_back(Box{Bounds3{{-2.5f, -0.5f, -0.5f}, {-1.5f, 0.5f, 0.5f}}});
    SimdPathGuard guard;
    for (BvhLayout layout : {BvhLayout::pairs, BvhLayout::wide8}) {
        AcceleratorOptions opt;
        opt.layout = layout;
        const Accelerator acc(scene, opt);
        check_wide8_valid(acc);
        for (SimdPath path : runnable_paths()) {
            force_simd_path(path);
            INFO(std::string(bvh_layout_name(layout)), " ", std::string(simd_path_name(path)));
            CHECK(disagreements(acc, make_random_rays(acc.bounds(), 20000 / kSanitizerDivisor, 91)) == 0);
        }
        TraversalCounters counters;
        Ray r{Vec3(0.0f, 0.0f, -5.0f), Vec3(0.0f, 0.0f, 1.0f)};
        Hit h;
        REQUIRE(acc.intersect_counted(r, h, counters));
        CHECK(counters.nodes_visited > 1);
        CHECK(counters.prims_tested > 0);
    }
    BvhLayout layout{};
    CHECK(parse_bvh_layout("pairs", layout));
    CHECK(layout == BvhLayout::pairs);
    CHECK(parse_bvh_layout(bvh_layout_name(BvhLayout::wide8), layout));
    CHECK(layout == BvhLayout::wide8);
    CHECK(std::string(bvh_layout_name(BvhLayout::pairs)) == "pairs");
    // The removed layouts are refused like any unknown name.
    CHECK_FALSE(parse_bvh_layout("wide4", layout));
    CHECK_FALSE(parse_bvh_layout("wide4-slots", layout));
    CHECK_FALSE(parse_bvh_layout("bvh8", layout));
    CHECK(layout == BvhLayout::wide8);
}

TEST_CASE("wide tree statistics follow Embree's definitions") {
    // One 8-wide node holding two leaves: unit cubes at x = 0 and x = 2, of 5 and 4
    // primitives (two blocks of four and one). Root box: 3 x 1 x 1, area 14; each leaf area 6.
    Bvh8 tree;
    tree.empty = false;
    tree.root.set_box(Bounds3{Vec3(0.0f), Vec3(3.0f, 1.0f, 1.0f)});
    tree.root.index = 0;
    tree.root.count = 0;
    Bvh8Node n{};
    for (int c = 0; c < 8; ++c) {
        n.lo_x[c] = n.lo_y[c] = n.lo_z[c] = kInfinity;
        n.hi_x[c] = n.hi_y[c] = n.hi_z[c] = -kInfinity;
        n.child[c] = kNoNode;
    }
    for (int c = 0; c < 2; ++c) {
        n.lo_x[c] = 2.0f * float(c), n.hi_x[c] = 2.0f * float(c) + 1.0f;
        n.lo_y[c] = n.lo_z[c] = 0.0f;
        n.hi_y[c] = n.hi_z[c] = 1.0f;
        n.child[c] = wide_leaf_ref(uint32_t(2 * c), c == 0 ? 5 : 4);  // first blocks 0 and 2
    }
    tree.nodes.push_back(n);
    const WideBvhStats s = compute_wide_bvh_stats(tree, 4);
    CHECK(s.nodes == 1);
    CHECK(s.children == 2);
    CHECK(s.leaves == 2);
    CHECK(s.leaf_primitives == 9);
    CHECK(s.leaf_blocks == 3);
    CHECK(s.sah_nodes == doctest::Approx(1.0));
    CHECK(s.sah_leaves == doctest::Approx((6.0 * 2 + 6.0 * 1) / 14.0));
    // Counted one primitive at a time (the slots layout), the leaves weigh 5 and 4.
    CHECK(compute_wide_bvh_stats(tree, 1).sah_leaves == doctest::Approx((6.0 * 5 + 6.0 * 4) / 14.0));

    // A built tree: every primitive in one leaf, every node but the first a child of another.
    const TriangleMesh mesh = make_icosphere(3);
    Scene scene;
    scene.triangles.positions = mesh.positions;
    scene.triangles.indices = mesh.indices;
    const Accelerator acc(scene);
    const WideBvhStats b = compute_wide_bvh_stats(acc.bvh8(), 4);
    CHECK(b.leaf_primitives == mesh.indices.size() / 3);
    CHECK(b.children == b.nodes - 1 + b.leaves);
    CHECK(b.sah_nodes >= 1.0);
    CHECK(b.leaf_blocks * 4 >= b.leaf_primitives);
}

namespace {

/// Every way to cut the subtree of binary node `x` into at most `limit` pieces
/// (x itself, or a cut of each child), as lists of binary node indices.
std::vector<std::vector<uint32_t>> cuts(const Bvh& bvh, uint32_t x, size_t limit) {
    std::vector<std::vector<uint32_t>> out{{x}};
    const BvhNode& n = bvh.nodes[x];
    if (n.is_leaf() || limit < 2) return out;
    for (const auto& a : cuts(bvh, n.index, limit - 1))
        for (const auto& b : cuts(bvh, n.index + 1, limit - a.size())) {
            std::vector<uint32_t> both = a;
            both.insert(both.end(), b.begin(), b.end());
            out.push_back(both);
        }
    return out;
}

/// Slots [first, first + count) of the subtree of `x`; first = kNoNode when not contiguous.
std::pair<uint32_t, uint32_t> slot_range(const Bvh& bvh, uint32_t x) {
    const BvhNode& n = bvh.nodes[x];
    if (n.is_leaf()) return {n.index, n.count};
    const auto l = slot_range(bvh, n.index), r = slot_range(bvh, n.index + 1);
    if (l.first == kNoNode || r.first != l.first + l.second) return {kNoNode, 0};
    return {l.first, l.second + r.second};
}

/// Least cost of any N-wide collapse of the subtree of inner node `x` (x's own node
/// included), by trying every cut: each wide node costs its surface area, each leaf
/// `block_cost` times its area and its blocks of four. A piece of a cut is a leaf of
/// the binary tree, an inner node (a wide node of its own) or, when it covers at most
/// `merge` contiguous slots, one merged leaf.
double least_cost(const Bvh& bvh, uint32_t x, size_t width, uint32_t merge, double block_cost,
                  std::map<uint32_t, double>& memo) {
    if (auto it = memo.find(x); it != memo.end()) return it->second;
    auto leaf_cost = [&](uint32_t y, uint32_t count) {
        return block_cost * double(bvh.nodes[y].box().surface_area()) * double((count + 3) / 4);
    };
    double best = std::numeric_limits<double>::infinity();
    const BvhNode& n = bvh.nodes[x];
    for (const auto& a : cuts(bvh, n.index, width - 1))
        for (const auto& b : cuts(bvh, n.index + 1, width - a.size())) {
            double sum = 0.0;
            for (const auto* part : {&a, &b})
                for (uint32_t y : *part) {
                    if (bvh.nodes[y].is_leaf()) {
                        sum += leaf_cost(y, bvh.nodes[y].count);
                        continue;
                    }
                    double c = least_cost(bvh, y, width, merge, block_cost, memo);
                    const auto range = slot_range(bvh, y);
                    if (range.first != kNoNode && range.second <= merge)
                        c = std::min(c, leaf_cost(y, range.second));
                    sum += c;
                }
            best = std::min(best, sum);
        }
    best += double(n.box().surface_area());
    memo[x] = best;
    return best;
}

}  // namespace

TEST_CASE("wide collapse: least SAH cost, as an exhaustive search finds it") {
    bool merged = false;  // some binary leaves were merged (the merging cases are not vacuous)
    for (const TriangleMesh& mesh : {make_icosphere(1), make_icosphere(2), make_slivers(150)}) {
        Scene scene;
        scene.triangles.positions = mesh.positions;
        scene.triangles.indices = mesh.indices;
        for (BvhLayout layout : {BvhLayout::wide8})
            for (const WideCollapse collapse :
                 {WideCollapse{0, 1.0}, WideCollapse{8, 1.0}, WideCollapse{8, 0.5}}) {
                INFO(mesh.name, " layout ", std::string(bvh_layout_name(layout)), " merge ",
                     collapse.merge_leaves_up_to, " block cost ", collapse.block_cost);
                AcceleratorOptions opt;
                opt.layout = layout;
                opt.collapse = collapse;
                opt.keep_binary_tree = true;
                opt.flat_loop_max_prims = 0;
                const Accelerator acc(scene, opt);
                const Bvh& bvh = acc.bvh();
                REQUIRE(!bvh.nodes[0].is_leaf());
                std::map<uint32_t, double> memo;
                const size_t width = 8;
                const double best =
                    least_cost(bvh, 0, width, collapse.merge_leaves_up_to, collapse.block_cost, memo) /
                    double(bvh.nodes[0].box().surface_area());
                const WideBvhStats s = compute_wide_bvh_stats(acc.bvh8(), 4);
                CHECK(s.sah_nodes + collapse.block_cost * s.sah_leaves ==
                      doctest::Approx(best).epsilon(1e-5));
                if (collapse.merge_leaves_up_to == 0) CHECK(s.leaves == (bvh.nodes.size() + 1) / 2);
                merged = merged || s.leaves < (bvh.nodes.size() + 1) / 2;
                check_wide8_valid(acc);
            }
    }
    CHECK(merged);
}

/// Whether the nodes are in the order of a serial depth-first emission: walking the inner
/// children in slot order, the k-th node reached is nodes[k].
template <int N>
bool depth_first_nodes(const BvhWide<N>& t) {
    size_t next = 0;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const size_t index = BvhWide<N>::index_of(stack.back());
        stack.pop_back();
        if (index != next++) return false;
        const BvhWideNode<N>& n = t.nodes[index];
        for (int c = N - 1; c >= 0; --c)
            if (n.has_child(c) && !n.leaf_count(c)) stack.push_back(n.child[c]);
    }
    return next == t.nodes.size();
}

TEST_CASE("wide collapse of a large tree: the same depth-first nodes for 1 to 3 threads and serially") {
    // 81920 triangles: enough binary nodes for the programme to run as tasks, each parent
    // combined by whichever thread ends its second child; the last tree is solved without
    // tasks.
    const Scene scene = scene_from_mesh(make_icosphere(6));
    for (const WideCollapse collapse : {WideCollapse{0, 1.0}, WideCollapse{8, 1.0}}) {
        AcceleratorOptions opt;
        opt.keep_binary_tree = true;
        opt.flat_loop_max_prims = 0;
        const Accelerator acc(scene, opt);
        const Bvh& bvh = acc.bvh();
        REQUIRE(bvh.nodes.size() > (size_t(1) << 14));
        const int saved = omp_get_max_threads();
        std::vector<Bvh8> trees;
        for (int threads = 1; threads <= 3; ++threads) {
            omp_set_num_threads(threads);
            trees.push_back(make_bvh_wide<8>(bvh, collapse));
        }
        WideCollapse serial = collapse;
        serial.parallel_min_nodes = bvh.nodes.size() + 1;
        trees.push_back(make_bvh_wide<8>(bvh, serial));
        omp_set_num_threads(saved);
        INFO("merge ", collapse.merge_leaves_up_to);
        CHECK(depth_first_nodes(trees[0]));
        CHECK(compute_wide_bvh_stats(trees[0], 4).leaves > 0);
        for (size_t t = 1; t < trees.size(); ++t) {
            REQUIRE(trees[t].nodes.size() == trees[0].nodes.size());
            size_t differ = 0;  // member by member: the nodes' padding is never written
            for (size_t i = 0; i < trees[0].nodes.size(); ++i) {
                const Bvh8Node &a = trees[0].nodes[i], &b = trees[t].nodes[i];
                differ += std::memcmp(a.lo_x, b.lo_x, sizeof a.lo_x) ||
                          std::memcmp(a.hi_x, b.hi_x, sizeof a.hi_x) ||
                          std::memcmp(a.lo_y, b.lo_y, sizeof a.lo_y) ||
                          std::memcmp(a.hi_y, b.hi_y, sizeof a.hi_y) ||
                          std::memcmp(a.lo_z, b.lo_z, sizeof a.lo_z) ||
                          std::memcmp(a.hi_z, b.hi_z, sizeof a.hi_z) ||
                          std::memcmp(a.child, b.child, sizeof a.child);
            }
            CHECK(differ == 0);
        }
    }
}

TEST_CASE("wide leaf references: the largest leaves, clamped leaf sizes, refused oversize leaves") {
    // Primitives cost far more than nodes, so the builder keeps leaves as large as it may:
    // a max_leaf_size of 1000 is clamped to the largest count a leaf reference holds.
    const TriangleMesh m = make_icosphere(3);
    const Scene scene = scene_from_mesh(m);
    const std::vector<Ray> rays = make_random_rays(mesh_bounds(m), 4000 / kSanitizerDivisor, 91);
    SimdPathGuard guard;
    for (BvhLayout layout : {BvhLayout::wide8}) {
        AcceleratorOptions opt;
        opt.layout = layout;
        opt.params.max_leaf_size = 1000;
        opt.params.intersection_cost = 1e-4f;
        opt.collapse.merge_leaves_up_to = kMaxWideLeafCount;
        opt.flat_loop_max_prims = 0;
        CHECK(opt.build_params().max_leaf_size == kMaxWideLeafCount);
        const Accelerator acc(scene, opt);
        check_wide8_valid(acc);
        uint32_t largest = 0;
        auto largest_leaf = [&](const auto& tree) {
            for (const auto& n : tree.nodes)
                for (int c = 0; c < std::decay_t<decltype(n)>::kWidth; ++c)
                    largest = std::max(largest, n.leaf_count(c));
        };
        largest_leaf(acc.bvh8());
        INFO("layout ", std::string(bvh_layout_name(layout)), " largest leaf ", largest);
        CHECK(largest > 32);  // the count's top bit is used
        CHECK(largest <= kMaxWideLeafCount);
        for (SimdPath path : runnable_paths()) {
            force_simd_path(path);
            INFO(std::string(simd_path_name(path)));
            CHECK(disagreements(acc, rays) == 0);
        }
    }
    // The collapse itself refuses leaves its references cannot hold.
    AcceleratorOptions big;
    big.layout = BvhLayout::pairs;  // keeps max_leaf_size unclamped
    big.params.max_leaf_size = 1000;
    big.params.intersection_cost = 1e-4f;
    big.flat_loop_max_prims = 0;
    const Accelerator pairs(scene, big);
    const Bvh& bvh = pairs.bvh();
    REQUIRE(!bvh.nodes.empty());
    CHECK(std::any_of(bvh.nodes.begin(), bvh.nodes.end(),
                      [](const BvhNode& n) { return n.is_leaf() && n.count > kMaxWideLeafCount; }));
    CHECK_THROWS_AS(make_bvh_wide<8>(bvh), std::invalid_argument);
    CHECK_THROWS_AS(make_bvh_wide<8>(bvh, WideCollapse{kMaxWideLeafCount + 1, 1.0}), std::invalid_argument);
}
