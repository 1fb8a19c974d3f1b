// Ray streams (accel/ray_stream.h): rays that go down the upper levels together and then
// finish alone from their frontiers (Accelerator::intersect_frontier) must find what
// each ray finds alone, on every SIMD path that streams.
#include <doctest/doctest.h>

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "accel/ray_stream.h"
#include "accel/simd_path.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Restores automatic SIMD path selection when a test ends.
struct SimdGuard {
    ~SimdGuard() { force_simd_path(best_simd_path()); }
};

/// The rays' hits, traced as streams of kMaxStreamRays consecutive rays.
std::vector<Hit> trace_streamed(const Accelerator& accel, const std::vector<Ray>& rays,
                                RayStreamStats& stats) {
    const auto stream = std::make_unique<RayStream>();
    std::vector<Hit> hits;
    for (size_t first = 0; first < rays.size(); first += kMaxStreamRays) {
        const size_t last = std::min(rays.size(), first + kMaxStreamRays);
        stream->clear();
        for (size_t k = first; k < last; ++k) stream->add(BvhRay(rays[k]));
        trace_stream_frontiers(accel.bvh8(), *stream, &stats);
        for (size_t k = first; k < last; ++k) {
            const size_t i = k - first;
            Ray r = rays[k];
            Hit h;
            if (stream->overflow[i])
                accel.intersect(r, h);
            else if (stream->frontier_count[i] > 0)
                accel.intersect_frontier(r, h, stream->frontier[i], stream->frontier_count[i]);
            hits.push_back(h);
        }
    }
    return hits;
}

/// Vertical and slanted rays onto a unit_grid at z = 0 that meet it exactly on shared
/// edges and vertices (the grid's and the quads' diagonals), in row order.
std::vector<Ray> edge_rays(int n) {
    std::vector<Ray> rays;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            for (int f = 0; f < 4; ++f) {
                // (i + f/4, j + f/4) / n lies on the quad's diagonal, f = 0 on a vertex.
                const float x = (float(i) + 0.25f * float(f)) / float(n),
                            y = (float(j) + 0.25f * float(f)) / float(n);
                rays.push_back(Ray{{x, y, 1.0f}, {0.0f, 0.0f, -1.0f}});
                rays.push_back(Ray{{x + 0.25f, y + 0.125f, 1.0f}, {-0.25f, -0.125f, -1.0f}});
                // On the edge x = i / n between two quads.
                rays.push_back(Ray{{float(i) / float(n), y, 2.0f}, {0.0f, 0.0f, -2.0f}});
            }
    return rays;
}

/// Checks every ray's streamed hit against intersect(). `exact`: the same distance,
/// triangle and uv, bit for bit. Otherwise (rays that meet two triangles at one point)
/// the same hit or miss, the distance within one ulp and no miss at all: the leaf test
/// accepts a distance against the current tmax before its last rounding, so which of
/// two such triangles wins, and the last bit of t, depend on the order of the visits.
void check_against_single_rays(const Accelerator& accel, const std::vector<Ray>& rays, bool exact) {
    RayStreamStats stats;
    const std::vector<Hit> streamed = trace_streamed(accel, rays, stats);
    int wrong = 0, missed = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
        Ray r = rays[k];
        Hit alone;
        const bool found = accel.intersect(r, alone);
        const Hit& s = streamed[k];
        if (!exact && !s.hit()) ++missed;
        bool same = found == s.hit();
        if (found && same) {
            const auto bits = [](float x) { return int64_t(std::bit_cast<uint32_t>(x)); };
            if (exact)
                same = bits(alone.t) == bits(s.t) && alone.prim == s.prim && bits(alone.u) == bits(s.u) &&
                       bits(alone.v) == bits(s.v);
            else
                same = std::abs(bits(alone.t) - bits(s.t)) <= 1;
        }
        if (!same) ++wrong;
    }
    CHECK(wrong == 0);
    CHECK(missed == 0);
    CHECK(stats.rays == rays.size());
    // The streams went below the root, so the walk and the frontiers were exercised.
    CHECK(stats.node_visits[1] > 0);
    CHECK(stats.frontier_entries > 0);
}

}  // namespace

TEST_CASE("ray streams: a scan mesh and random rays give intersect's hits on every streaming SIMD path") {
    const TriangleMesh mesh = make_scan_mesh(90, 140, 6, 3);
    const Scene scene = scene_from_mesh(mesh);
    const Accelerator accel(scene);
    // Unsorted, a quarter axis-parallel (zero direction components: infinite inverses).
    const std::vector<Ray> rays = make_random_rays(accel.bounds(), 6000, 11);
    SimdGuard guard;
    int paths = 0;
    for (const SimdPath path : runnable_simd_paths()) {
        force_simd_path(path);
        if (!accel.stream_traversal_supported()) continue;
        CAPTURE(std::string(simd_path_name(path)));
        ++paths;
        check_against_single_rays(accel, rays, true);
    }
    if (best_simd_path() != SimdPath::sse2) CHECK(paths > 0);
}

TEST_CASE("ray streams: rays onto shared edges and vertices of a grid all hit within an ulp of intersect") {
    const TriangleMesh mesh = unit_grid(48, 0.0f, 0);
    const Scene scene = scene_from_mesh(mesh);
    const Accelerator accel(scene);
    const std::vector<Ray> rays = edge_rays(48);
    SimdGuard guard;
    for (const SimdPath path : runnable_simd_paths()) {
        force_simd_path(path);
        if (!accel.stream_traversal_supported()) continue;
        CAPTURE(std::string(simd_path_name(path)));
        check_against_single_rays(accel, rays, false);
    }
}
