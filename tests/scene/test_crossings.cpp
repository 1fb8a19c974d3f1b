// collect_crossings / count_crossings: every crossing along a ray, a ray through a
// shared edge or vertex counted once, parity exact on a closed mesh.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "accel/crossings.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/mesh_scene.h"

using namespace sahara;
using sahara::test::make_icosphere;

namespace {

struct CrossingFixture {
    TriangleMesh mesh = make_icosphere(2);
    Scene scene = scene_from_mesh(mesh);
    Accelerator accel{scene};

    uint32_t count(const Vec3& origin, const Vec3& dir) const {
        Ray r;
        r.origin = origin;
        r.dir = dir;
        return count_crossings(accel.bvh8(), std::span<const TriangleBlock4>(accel.leaf_blocks()), r);
    }
};

}  // namespace

TEST_CASE("crossings: rays through icosphere vertices and edge midpoints cross once") {
    const CrossingFixture f;
    for (const Vec3& p : f.mesh.positions) {
        CHECK(f.count(Vec3(0.0f), p) == 1);
        CHECK(f.count(p * -2.0f, p * 3.0f) == 2);
    }
    for (size_t t = 0; t < f.mesh.triangle_count(); ++t) {
        const Vec3 a = f.mesh.positions[f.mesh.indices[3 * t]],
                   b = f.mesh.positions[f.mesh.indices[3 * t + 1]];
        const Vec3 mid = (a + b) * 0.5f;
        CHECK(f.count(Vec3(0.0f), mid) == 1);
        CHECK(f.count(mid * 0.25f, mid) == 1);
    }
}

TEST_CASE("crossings: parity tells inside from outside and the hits carry their triangle") {
    const CrossingFixture f;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.5f, 1.5f);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng)), d(u(rng), u(rng), u(rng));
        const float r = length(p);
        if (r > 0.95f && r < 1.0f) continue;  // between the inscribed and the circumscribed sphere
        CHECK((f.count(p, d) % 2 == 1) == (r < 0.95f));
    }
    Ray ray;
    ray.origin = Vec3(0.1f, 0.2f, -3.0f);
    ray.dir = Vec3(0.0f, 0.0f, 1.0f);
    std::vector<Hit> hits;
    collect_crossings(f.accel.bvh8(), std::span<const TriangleBlock4>(f.accel.leaf_blocks()), ray, hits);
    REQUIRE(hits.size() == 2);
    for (const Hit& h : hits) CHECK(prim_index(h.prim) < f.mesh.triangle_count());
    // The chord of the unit sphere at distance |(0.1, 0.2)| from the centre, up to the facets.
    CHECK(std::fabs(std::fabs(hits[0].t - hits[1].t) - 2.0f * std::sqrt(0.95f)) < 0.05f);
}
