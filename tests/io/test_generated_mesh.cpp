// The in-memory mesh of `sahara bench --generated-mesh` (io/generated_mesh.h):
// exact triangle counts and a closed, outward-wound surface.
#include <doctest/doctest.h>

#include <map>
#include <stdexcept>
#include <utility>

#include "io/generated_mesh.h"
#include "io/mesh_utils.h"

using namespace sahara;

namespace {

/// Every directed edge a -> b of the mesh and how often triangles use it.
std::map<std::pair<uint32_t, uint32_t>, int> directed_edges(const TriangleMesh& m) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k)
            ++edges[{m.indices[3 * t + size_t(k)], m.indices[3 * t + size_t(k + 1) % 3]}];
    return edges;
}

/// Signed volume by the divergence theorem: positive when the triangles face outwards.
double signed_volume(const TriangleMesh& m) {
    double v = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        double p[3][3];
        for (int k = 0; k < 3; ++k) {
            const Vec3 q = m.positions[m.indices[3 * t + size_t(k)]];
            p[k][0] = double(q.x), p[k][1] = double(q.y), p[k][2] = double(q.z);
        }
        // a . (b x c) / 6: the tetrahedron of the triangle and the origin.
        v += (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
              p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
              p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0])) /
             6.0;
    }
    return v;
}

}  // namespace

TEST_CASE("generated sphere: exactly the triangles asked for - also for awkward counts") {
    for (size_t n : {6ul, 8ul, 12ul, 1000ul, 4094ul /* 2 * 23 * 89 */, 20002ul /* 2 * 10001 = 2 * 73 * 137 */,
                     2 * 5003ul /* 5003 prime: one ring */}) {
        CAPTURE(n);
        const SphereGrid g = sphere_grid_for(n);
        CHECK(g.triangles() == n);
        CHECK(g.segments >= 3);
        const TriangleMesh m = make_displaced_sphere(g);
        CHECK(m.triangle_count() == n);
        CHECK(m.positions.size() == size_t(g.rings) * g.segments + 2);
    }
    // 10 million: 1600 rings of 3125 segments, close to square quads.
    const SphereGrid big = sphere_grid_for(10'000'000);
    CHECK(big.rings == 1600);
    CHECK(big.segments == 3125);
}

TEST_CASE("generated sphere: odd and tiny counts are refused") {
    CHECK_THROWS_AS(sphere_grid_for(0), std::invalid_argument);
    CHECK_THROWS_AS(sphere_grid_for(4), std::invalid_argument);
    CHECK_THROWS_AS(sphere_grid_for(1001), std::invalid_argument);
}

TEST_CASE(
    "generated sphere: closed - every edge used once each way - outward and without degenerate triangles") {
    for (size_t n : {6ul, 96ul, 4094ul, 20000ul}) {
        CAPTURE(n);
        const TriangleMesh m = make_displaced_sphere(sphere_grid_for(n));
        const auto edges = directed_edges(m);
        bool closed = true;
        for (const auto& [e, count] : edges) {
            const auto back = edges.find({e.second, e.first});
            closed = closed && count == 1 && back != edges.end() && back->second == 1;
        }
        CHECK(closed);
        // Euler characteristic of a sphere: V - E + F = 2.
        CHECK(int64_t(m.positions.size()) - int64_t(edges.size() / 2) + int64_t(m.triangle_count()) == 2);
        // Outward: positive; fine grids come near a unit sphere's 4.19 (the 6-triangle bicone: 0.85).
        CHECK(signed_volume(m) > (n >= 4094 ? 3.5 : 0.5));
        size_t degenerate = 0;
        for (size_t t = 0; t < m.triangle_count(); ++t)
            degenerate += is_degenerate(m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
                                        m.positions[m.indices[3 * t + 2]]);
        CHECK(degenerate == 0);
        const Bounds3 b = mesh_bounds(m);
        CHECK(b.lo.x > -1.3f);
        CHECK(b.hi.y < 1.3f);
    }
}

TEST_CASE("generated sphere: the same count gives the same mesh") {
    const TriangleMesh a = make_displaced_sphere(sphere_grid_for(5000)),
                       b = make_displaced_sphere(sphere_grid_for(5000));
    CHECK(a.indices == b.indices);
    CHECK(std::equal(a.positions.begin(), a.positions.end(), b.positions.begin(),
                     [](const Vec3& p, const Vec3& q) { return p.x == q.x && p.y == q.y && p.z == q.z; }));
}
