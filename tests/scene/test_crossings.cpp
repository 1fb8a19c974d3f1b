// collect_crossings / count_crossings: every crossing along a ray, a ray through a
// shared edge or vertex counted once, parity exact on a closed mesh.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <utility>
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

namespace {

/// The cube [-1, 1]^3, each face split into two triangles along a diagonal (the two
/// diagonal directions alternate between faces), wound outward.
TriangleMesh make_split_cube() {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i)  // corner i: bit 0 x, bit 1 y, bit 2 z (1: +1)
        m.positions.push_back(Vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f));
    const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int f = 0; f < 6; ++f) {
        const uint32_t* q = quads[f];
        const uint32_t tris[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
        const uint32_t other[2][3] = {{q[0], q[1], q[3]}, {q[1], q[2], q[3]}};
        for (const auto& t : (f % 2 ? other : tris)) m.indices.insert(m.indices.end(), t, t + 3);
    }
    return m;
}

/// Crossing counts over one mesh, and the number of hits collect_crossings gives.
struct MeshCrossings {
    explicit MeshCrossings(TriangleMesh m) : mesh(std::move(m)), scene(scene_from_mesh(mesh)), accel(scene) {}
    TriangleMesh mesh;
    Scene scene;
    Accelerator accel;

    uint32_t count(const Vec3& origin, const Vec3& dir) const {
        Ray r;
        r.origin = origin;
        r.dir = dir;
        const std::span<const TriangleBlock4> blocks(accel.leaf_blocks());
        std::vector<Hit> hits;
        collect_crossings(accel.bvh8(), blocks, r, hits);
        const uint32_t n = count_crossings(accel.bvh8(), blocks, r);
        CHECK(hits.size() == n);
        return n;
    }
};

/// Whether `p` is inside the convex closed mesh, in double: +1 inside, -1 outside,
/// 0 within `margin` of a face plane (undecided, skipped).
int convex_side(const TriangleMesh& m, const Vec3& p, double margin) {
    int side = 1;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        double v[3][3];
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) v[k][a] = double(m.positions[m.indices[3 * t + size_t(k)]][a]);
        const double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
        const double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double d = 0.0;
        for (int a = 0; a < 3; ++a) d += n[a] / len * (double(p[a]) - v[0][a]);
        if (std::fabs(d) < margin) return 0;
        if (d > 0.0) side = -1;
    }
    return side;
}

}  // namespace

TEST_CASE("crossings: split cube rays exactly through vertices and edges count the right parity") {
    const MeshCrossings f(make_split_cube());
    std::mt19937 rng(11);
    // Targets on the surface: corners and dyadic points of every triangle edge (the
    // face diagonals included); directions with small power-of-two components, origins
    // a dyadic step back. Every operation of the test is then exact in float, so the
    // rays pass exactly through the target, which is what the tie-break must resolve.
    std::uniform_int_distribution<int> tri(0, int(f.mesh.triangle_count()) - 1), corner(0, 2), eighth(0, 7),
        comp(-3, 3), step(1, 16);
    const float kComponent[7] = {-4.0f, -2.0f, -1.0f, 0.0f, 1.0f, 2.0f, 4.0f};
    int tested = 0, inside = 0;
    for (int i = 0; i < 20000; ++i) {
        const size_t t = size_t(tri(rng));
        const int k = corner(rng);
        const Vec3 a = f.mesh.positions[f.mesh.indices[3 * t + size_t(k)]];
        const Vec3 b = f.mesh.positions[f.mesh.indices[3 * t + size_t((k + 1) % 3)]];
        const Vec3 target = a + (b - a) * (float(eighth(rng)) / 8.0f);
        const Vec3 dir(kComponent[comp(rng) + 3], kComponent[comp(rng) + 3], kComponent[comp(rng) + 3]);
        if (dir == Vec3(0.0f)) continue;
        const Vec3 origin = target - dir * (float(step(rng)) / 32.0f);
        const float m = std::max(std::fabs(origin.x), std::max(std::fabs(origin.y), std::fabs(origin.z)));
        if (m == 1.0f) continue;  // on a face plane: on the surface or beside it
        ++tested;
        inside += m < 1.0f;
        CHECK((f.count(origin, dir) % 2 == 1) == (m < 1.0f));
    }
    CHECK(tested > 15000);
    CHECK(inside > 1000);
}

TEST_CASE("crossings: axis rays exactly through icosphere vertices count the right parity") {
    const MeshCrossings f(make_icosphere(3));
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> coord(-1.5f, 1.5f);
    std::uniform_int_distribution<int> axis(0, 2), sign(0, 1);
    std::uniform_int_distribution<size_t> vertex(0, f.mesh.positions.size() - 1);
    int tested = 0, inside = 0;
    for (int i = 0; i < 20000; ++i) {
        // The origin shares two coordinates with the vertex, so the ray along the third
        // axis passes exactly through it (the shear of an axis ray is 0).
        const Vec3 v = f.mesh.positions[vertex(rng)];
        const int a = axis(rng);
        Vec3 origin = v, dir(0.0f);
        origin[a] = coord(rng);
        dir[a] = sign(rng) ? 1.0f : -1.0f;
        const int side = convex_side(f.mesh, origin, 1e-5);
        if (side == 0) continue;
        ++tested;
        inside += side > 0;
        CHECK((f.count(origin, dir) % 2 == 1) == (side > 0));
    }
    CHECK(tested > 15000);
    CHECK(inside > 1000);
}

TEST_CASE("crossings: random rays through icosphere edge midpoints count the right parity") {
    const MeshCrossings f(make_icosphere(3));
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> coord(-1.5f, 1.5f);
    std::uniform_int_distribution<size_t> tri(0, f.mesh.triangle_count() - 1);
    int tested = 0;
    for (int i = 0; i < 20000; ++i) {
        // Aimed at an edge's midpoint, up to rounding: the rays within a few ulps of
        // the edge, where a test without a consistent tie-break slips or counts twice.
        const size_t t = tri(rng);
        const Vec3 mid =
            (f.mesh.positions[f.mesh.indices[3 * t]] + f.mesh.positions[f.mesh.indices[3 * t + 1]]) * 0.5f;
        const Vec3 origin(coord(rng), coord(rng), coord(rng));
        const int side = convex_side(f.mesh, origin, 1e-5);
        if (side == 0 || length(mid - origin) < 1e-3f) continue;
        ++tested;
        CHECK((f.count(origin, mid - origin) % 2 == 1) == (side > 0));
    }
    CHECK(tested > 15000);
}

namespace {

/// A closed box of big wall triangles around an icosphere, and big triangles across the
/// box: spatial splits cut them.
TriangleMesh make_walled_sphere() {
    TriangleMesh m = make_icosphere(3, 0.3f, Vec3(0.4f, 0.2f, 0.1f));
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(-1.9f, 1.9f);
    for (int i = 0; i < 30; ++i) {
        const auto base = uint32_t(m.positions.size());
        for (int k = 0; k < 3; ++k) m.positions.push_back(Vec3(u(rng), u(rng), u(rng)));
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    const Vec3 c[8] = {{-2, -2, -2}, {2, -2, -2}, {2, 2, -2}, {-2, 2, -2},
                       {-2, -2, 2},  {2, -2, 2},  {2, 2, 2},  {-2, 2, 2}};
    const uint32_t faces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                  {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 2, 6, 5}};
    for (const auto& f : faces) {
        const auto base = uint32_t(m.positions.size());
        for (const uint32_t k : f) m.positions.push_back(c[k]);
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

uint32_t brute_force_crossings(const TriangleMesh& m, const Ray& r) {
    const TriangleRay tr(r);
    uint32_t n = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        const Vec3* p = m.positions.data();
        const uint32_t* i = &m.indices[3 * t];
        n += TriangleVerts::of(p[i[0]], p[i[1]], p[i[2]]).intersect(tr, r.tmin, r.tmax).has_value();
    }
    return n;
}

}  // namespace

TEST_CASE("crossings: the crossings options reference each triangle once where sbvh splits") {
    const TriangleMesh m = make_walled_sphere();
    const Scene scene = scene_from_mesh(m);
    AcceleratorOptions split_options;
    split_options.builder = BvhBuilder::sbvh;
    const Accelerator split(scene, split_options), once(scene, crossings_accelerator_options());
    REQUIRE(split.has_split_references());
    CHECK_FALSE(once.has_split_references());
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.9f, 1.9f);
    int split_wrong = 0, once_wrong = 0;
    for (int i = 0; i < 2000; ++i) {
        Ray r;
        r.origin = Vec3(u(rng), u(rng), u(rng));
        r.dir = normalize(Vec3(u(rng), u(rng), u(rng)));
        const uint32_t expected = brute_force_crossings(m, r);
        const std::span<const TriangleBlock4> split_blocks(split.leaf_blocks()),
            once_blocks(once.leaf_blocks());
        split_wrong += count_crossings(split.bvh8(), split_blocks, r) != expected;
        once_wrong += count_crossings(once.bvh8(), once_blocks, r) != expected;
    }
    // The split tree counts a wall once per leaf the ray enters: the scene exposes the
    // double count, and the crossings options must not have it.
    CHECK(split_wrong > 0);
    CHECK(once_wrong == 0);
}
