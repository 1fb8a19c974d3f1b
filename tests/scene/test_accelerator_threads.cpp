#include <doctest/doctest.h>
#include <omp.h>

#include <cstring>
#include <vector>

#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"
#include "scene/scene.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Restores the thread count when a test ends.
struct ThreadCountGuard {
    int threads = omp_get_max_threads();
    ~ThreadCountGuard() { omp_set_num_threads(threads); }
};

/// The wide tree's nodes and leaf blocks, byte for byte.
std::vector<unsigned char> wide_bytes(const Accelerator& acc) {
    const auto& nodes = acc.bvh8().nodes;
    const auto& blocks = acc.leaf_blocks();
    const size_t node_bytes = nodes.size() * sizeof(nodes[0]),
                 block_bytes = blocks.size() * sizeof(blocks[0]);
    std::vector<unsigned char> out(node_bytes + block_bytes);
    std::memcpy(out.data(), nodes.data(), node_bytes);
    std::memcpy(out.data() + node_bytes, blocks.data(), block_bytes);
    return out;
}

}  // namespace

TEST_CASE("the accelerator's wide tree and leaf blocks are the same at 1 to 3 threads") {
    ThreadCountGuard guard;
    // Large enough for the build's shared team (and every stage's tasks), with spheres
    // so that leaf blocks also carry other kinds.
    Scene scene = scene_from_mesh(make_scan_mesh_70k());
    for (int i = 0; i < 40; ++i) scene.spheres.push_back(Sphere{Vec3(0.05f * float(i), 0.0f, 0.0f), 0.02f});
    omp_set_num_threads(1);
    const Accelerator serial(scene);
    REQUIRE(serial.uses_tree());
    REQUIRE(serial.bvh8().nodes.size() > 1000);
    const std::vector<unsigned char> expected = wide_bytes(serial);
    for (int threads = 2; threads <= 3; ++threads) {
        CAPTURE(threads);
        omp_set_num_threads(threads);
        const Accelerator acc(scene);
        CHECK(acc.primitive_count() == serial.primitive_count());
        CHECK(wide_bytes(acc) == expected);
    }
}
