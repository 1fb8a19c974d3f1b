#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "accel/simd_path.h"
#include "scene/accelerator.h"
#include "base/error.h"
#include "io/mesh_triangles.h"
#include "scene/mesh_scene.h"
#include "geometry/triangle.h"
#include "mesh_fixtures.h"
#include "scene/scene.h"
#include "scratch_dir.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Restores automatic SIMD path selection when a test ends.
struct SimdPathGuard {
    ~SimdPathGuard() { force_simd_path(best_simd_path()); }
};

bool hit_triangle(const Ray& r, const Vec3& a, const Vec3& b, const Vec3& c, ShapeHit& h) {
    const std::optional<ShapeHit> hit = TriangleVerts::of(a, b, c).intersect(r);
    if (hit) h = *hit;
    return hit.has_value();
}

}  // namespace

TEST_CASE("triangle hit gives t and barycentrics of vertices 1 and 2") {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    ShapeHit h{};
    REQUIRE(hit_triangle(Ray{{0.25f, 0.5f, 2}, {0, 0, -2}}, a, b, c, h));
    CHECK(h.t == doctest::Approx(1.0f));
    CHECK(h.u == doctest::Approx(0.25f));
    CHECK(h.v == doctest::Approx(0.5f));
    // Back side hits too (no culling), with the same barycentrics.
    REQUIRE(hit_triangle(Ray{{0.25f, 0.5f, -1}, {0, 0, 1}}, a, b, c, h));
    CHECK(h.t == doctest::Approx(1.0f));
    CHECK(h.u == doctest::Approx(0.25f));
    // Outside, behind the origin, beyond tmax, and exactly at tmax (open interval).
    CHECK(!hit_triangle(Ray{{0.75f, 0.75f, 1}, {0, 0, -1}}, a, b, c, h));
    CHECK(!hit_triangle(Ray{{0.25f, 0.25f, -1}, {0, 0, -1}}, a, b, c, h));
    CHECK(!hit_triangle(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0.0f, 0.5f}, a, b, c, h));
    CHECK(!hit_triangle(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 0.0f, 1.0f}, a, b, c, h));
    CHECK(!hit_triangle(Ray{{0.25f, 0.25f, 1}, {0, 0, -1}, 1.0f, 2.0f}, a, b, c, h));
}

TEST_CASE("TriangleRay::scattered gives the constructor's axes and shear, ties and signed zeros included") {
    // Components drawn from a small set, so that ties between |x|, |y|, |z|, negative
    // zeros and every dominant axis and sign occur many times.
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 3.0f, -3.0f, 1e-30f, -2.5e7f};
    int checked = 0, mismatched = 0;
    for (float x : values)
        for (float y : values)
            for (float z : values) {
                if (x == 0.0f && y == 0.0f && z == 0.0f) continue;  // no direction
                const Ray r{{0.25f, -1.5f, 2.0f}, {x, y, z}};
                const float inv[3] = {1.0f / x, 1.0f / y, 1.0f / z};  // as BvhRay has them
                const TriangleRay a(r);
                // With the box test's inverse direction, and dividing itself.
                for (const TriangleRay& b :
                     {TriangleRay::scattered(r, inv), TriangleRay::scattered(r, nullptr)}) {
                    ++checked;
                    if (a.kx != b.kx || a.ky != b.ky || a.kz != b.kz || std::memcmp(&a.sx, &b.sx, 4) ||
                        std::memcmp(&a.sy, &b.sy, 4) || std::memcmp(&a.sz, &b.sz, 4) ||
                        std::memcmp(a.org, b.org, sizeof a.org))
                        ++mismatched;
                }
            }
    CHECK(checked == 2 * 992);  // 1000 less the eight all-zero combinations of +0 and -0, twice
    CHECK(mismatched == 0);
}

TEST_CASE("degenerate triangles never hit") {
    ShapeHit h{};
    const Ray r{{0.5f, 0, 1}, {0, 0, -1}};
    CHECK(!hit_triangle(r, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}, h));
    CHECK(!hit_triangle(r, {0.5f, 0, 0}, {0.5f, 0, 0}, {0.5f, 0, 0}, h));
    CHECK(!hit_triangle(Ray{{0, 0, 1}, {0, 0, -1}}, {0, 0, 0}, {0, 0, 0}, {1, 1, 0}, h));
}

TEST_CASE("rays aimed at the shared diagonal of a quad hit one of its triangles") {
    // Quad split along the diagonal; rays through points of the diagonal must hit at least one.
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(0, 1, 0);
    int lost = 0;
    for (int i = 1; i < 1000; ++i) {
        const float s = float(i) / 1000.0f;
        ShapeHit h{};
        const Vec3 target(s, s, 0);
        const Ray aimed{target + Vec3(0.3f, -0.7f, 2.0f), target - (target + Vec3(0.3f, -0.7f, 2.0f))};
        if (!hit_triangle(aimed, a, b, c, h) && !hit_triangle(aimed, a, c, d, h)) ++lost;
    }
    CHECK(lost == 0);
}

TEST_CASE("watertight: rays from inside a closed icosphere at vertices and edge midpoints never escape") {
    const TriangleMesh m = make_icosphere(3, 1.0f, {0.3f, -0.2f, 0.1f});
    Scene scene = scene_from_mesh(m);
    const Accelerator acc(scene);
    // Targets: every vertex and every edge midpoint (computed in float, so near the edge).
    std::vector<Vec3> targets = m.positions;
    for (size_t i = 0; i < m.indices.size(); i += 3)
        for (int k = 0; k < 3; ++k)
            targets.push_back(
                (m.positions[m.indices[i + size_t(k)]] + m.positions[m.indices[i + size_t((k + 1) % 3)]]) *
                0.5f);
    const int rays = 1000000 / kSanitizerDivisor;
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-0.6f, 0.6f);
    int escapes = 0, occl_escapes = 0;
    for (int i = 0; i < rays; ++i) {
        const Vec3 o = Vec3(0.3f, -0.2f, 0.1f) + Vec3(u(rng), u(rng), u(rng)) * 0.9f;
        const Vec3& target = targets[size_t(i) % targets.size()];
        Ray r{o, target - o};
        Hit h;
        if (!acc.intersect(r, h)) ++escapes;
        if (!acc.occluded(Ray{o, target - o})) ++occl_escapes;
    }
    CHECK(escapes == 0);
    CHECK(occl_escapes == 0);
}

TEST_CASE("watertight: brute-force triangle loop, rays through vertices of a closed icosphere") {
    const TriangleMesh m = make_icosphere(2);
    std::vector<TriangleVerts> tris;
    for (size_t i = 0; i < m.indices.size(); i += 3)
        tris.push_back(TriangleVerts::of(m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                                         m.positions[m.indices[i + 2]]));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-0.5f, 0.5f);
    int escapes = 0;
    for (int i = 0; i < 20000 / kSanitizerDivisor; ++i) {
        const Vec3 o(u(rng), u(rng), u(rng));
        const Ray r{o, m.positions[size_t(i) % m.positions.size()] - o};
        const TriangleRay tr(r);
        bool any = false;
        for (const TriangleVerts& t : tris) any |= t.intersect(tr, r.tmin, r.tmax).has_value();
        if (!any) ++escapes;
    }
    CHECK(escapes == 0);
}

namespace {

/// A closed fan: `n` triangles around `center`, their outer vertices on a ring of radius
/// `r` with a little height, so that the fan is not planar and no edge lies along an axis;
/// beyond it, a ring of small triangles (lateral distance 3 r and more) that gives the
/// tree inner nodes, so that the fan's triangles sit in leaves below them.
TriangleMesh fan_mesh(Vec3 center, float r, int n) {
    TriangleMesh m;
    m.name = "fan";
    m.positions.push_back(center);
    for (int i = 0; i < n; ++i) {
        const float a = 6.2831853f * (float(i) + 0.137f * float(i % 3)) / float(n);
        m.positions.push_back(center +
                              Vec3(r * std::cos(a), r * std::sin(a), 0.05f * r * float((i * 5) % 3 - 1)));
    }
    for (int i = 0; i < n; ++i)
        m.indices.insert(m.indices.end(), {0u, uint32_t(1 + i), uint32_t(1 + (i + 1) % n)});
    for (int k = 0; k < 64; ++k) {
        const float a = 6.2831853f * float(k) / 64.0f, d = r * (3.0f + float(k % 4));
        const uint32_t base = uint32_t(m.positions.size());
        const Vec3 p = center + Vec3(d * std::cos(a), d * std::sin(a), 0.0f);
        m.positions.insert(m.positions.end(),
                           {p, p + Vec3(0.2f * r, 0, 0), p + Vec3(0, 0.2f * r, 0.01f * r)});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    return m;
}

}  // namespace

TEST_CASE(
    "watertight: rays at the shared edges and the centre of a fan hit it on every SIMD path, near and far") {
    struct Placement {
        Vec3 center;
        float radius;
    };
    // Near the world origin, some thousands away, and a few hundred thousand away (where a
    // float's spacing is 1/32), the fan scaled so that it spans many of those steps.
    const Placement placements[] = {{{0.3f, -0.2f, 0.1f}, 1.0f},
                                    {{1000.5f, -2000.25f, 500.0f}, 1.0f},
                                    {{-3.0e5f, 1.0e5f, 2.0e5f}, 64.0f}};
    SimdPathGuard guard;
    int rays = 0, lost = 0, lost_occlusion = 0, lost_scalar = 0;
    for (const int n : {4, 7})
        for (const Placement& pl : placements) {
            const TriangleMesh m = fan_mesh(pl.center, pl.radius, n);
            Scene scene = scene_from_mesh(m);
            std::vector<TriangleVerts> fan;
            for (int i = 0; i < n; ++i)
                fan.push_back(TriangleVerts::of(m.positions[0], m.positions[size_t(1 + i)],
                                                m.positions[size_t(1 + (i + 1) % n)]));
            // The shared vertex exactly, and points of the shared (inner) edges, rounded to float.
            std::vector<Vec3> targets = {m.positions[0]};
            for (int i = 0; i < n; ++i)
                for (int k = 1; k < 10; ++k)
                    targets.push_back(m.positions[0] +
                                      (m.positions[size_t(1 + i)] - m.positions[0]) * (0.1f * float(k)));
            for (SimdPath path : runnable_simd_paths()) {
                force_simd_path(path);
                const Accelerator acc(scene);
                // Origins above the fan (within 60 degrees of its axis), from two radii
                // to ten thousand radii away.
                for (const float dist : {2.0f, 50.0f, 1.0e4f})
                    for (int o = 0; o < 6; ++o) {
                        const float a = 1.1f * float(o), tilt = 0.15f * float(o % 4);
                        const Vec3 origin =
                            pl.center + Vec3(std::sin(tilt) * std::cos(a), std::sin(tilt) * std::sin(a),
                                             o % 2 ? std::cos(tilt) : -std::cos(tilt)) *
                                            (dist * pl.radius);
                        for (const Vec3& target : targets) {
                            ++rays;
                            const Ray r{origin, target - origin};
                            Ray closest = r;
                            Hit h;
                            if (!acc.intersect(closest, h) || prim_index(h.prim) >= uint32_t(n)) ++lost;
                            if (!acc.occluded(Ray{origin, target - origin, 0.0f, 1.5f})) ++lost_occlusion;
                            const TriangleRay tr(r);
                            bool any = false;
                            for (const TriangleVerts& t : fan)
                                any |= t.intersect(tr, r.tmin, r.tmax).has_value();
                            if (!any) ++lost_scalar;
                        }
                    }
            }
        }
    CHECK(rays > 2000);
    CHECK(lost == 0);
    CHECK(lost_occlusion == 0);
    CHECK(lost_scalar == 0);
}

TEST_CASE("geometric normal, shading normal and uv interpolation") {
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2};
    CHECK(triangle_geometric_normal(m, 0) == Vec3(0, 0, 1));
    CHECK(triangle_shading_normal(m, 0, 0.2f, 0.3f) == Vec3(0, 0, 1));  // no normals: geometric
    m.normals = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    const Vec3 n = triangle_shading_normal(m, 0, 0.5f, 0.0f);
    CHECK(n.x == doctest::Approx(std::sqrt(0.5f)));
    CHECK(n.z == doctest::Approx(std::sqrt(0.5f)));
    m.uvs = {{0, 0}, {1, 0}, {0, 2}};
    const Vec2 uv = triangle_uv(m, 0, 0.25f, 0.5f);
    CHECK(uv.x == doctest::Approx(0.25f));
    CHECK(uv.y == doctest::Approx(1.0f));
    // Clockwise winding flips the geometric normal.
    m.indices = {0, 2, 1};
    CHECK(triangle_geometric_normal(m, 0) == Vec3(0, 0, -1));
}

TEST_CASE("OBJ reader fan-splits polygons in file order and keeps degenerate triangles") {
    const auto dir = test::scratch_dir("test_obj");
    const auto file = dir / "fan.obj";
    {
        std::FILE* f = std::fopen(file.string().c_str(), "w");
        REQUIRE(f);
        std::fputs("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 1 2 5\nf -5 -4 -3\n", f);
        std::fclose(f);
    }
    const TriangleMesh m = read_obj_triangles(file);
    REQUIRE(m.triangle_count() == 4);
    CHECK(m.indices == std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 4, 0, 1, 2});
    CHECK_THROWS_AS(read_obj_triangles(dir / "missing.obj"), InputError);
    std::filesystem::remove_all(dir);
}
