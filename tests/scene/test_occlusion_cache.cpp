// Occlusion rays on a generated interior: the shadow cache (OcclusionCache) and the
// any-hit child order (OcclusionOrder) change what the traversal costs, never its answers.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "accel/simd_path.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "scene/scene.h"
#include "sanitizer_build.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// An axis-aligned box as 12 triangles.
TriangleMesh box_mesh(Vec3 lo, Vec3 hi) {
    TriangleMesh m;
    m.name = "box";
    for (int k = 0; k < 8; ++k)
        m.positions.push_back({k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z});
    m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    return m;
}

/// A room 10 x 8 x 3 of slab walls with a window in the wall at y = 8, furnished with
/// rows of small boxes (chairs, books): an enclosure whose shell stops most rays, and
/// clutter around their origins that rarely does.
SceneDesc room() {
    SceneDesc d;
    d.materials.push_back(MaterialDesc{});
    d.meshes.push_back(box_mesh({0, 0, -0.2f}, {10, 8, 0}));  // floor
    d.meshes.push_back(box_mesh({0, 0, 3}, {10, 8, 3.2f}));   // ceiling
    d.meshes.push_back(box_mesh({-0.2f, 0, 0}, {0, 8, 3}));   // walls x = 0, x = 10, y = 0
    d.meshes.push_back(box_mesh({10, 0, 0}, {10.2f, 8, 3}));
    d.meshes.push_back(box_mesh({0, -0.2f, 0}, {10, 0, 3}));
    // Wall y = 8 around a window x in [3, 6], z in [1, 2.5].
    d.meshes.push_back(box_mesh({0, 8, 0}, {3, 8.2f, 3}));
    d.meshes.push_back(box_mesh({6, 8, 0}, {10, 8.2f, 3}));
    d.meshes.push_back(box_mesh({3, 8, 0}, {6, 8.2f, 1}));
    d.meshes.push_back(box_mesh({3, 8, 2.5f}, {6, 8.2f, 3}));
    for (int j = 0; j < 20; ++j)
        for (int i = 0; i < 25; ++i) {
            const Vec3 lo{0.2f + 0.4f * float(i), 0.2f + 0.38f * float(j), 0.0f};
            d.meshes.push_back(
                box_mesh(lo, lo + Vec3(0.1f, 0.1f, 0.1f + 0.05f * float((i * 7 + j * 3) % 5))));
        }
    return d;
}

/// Rays from a grid of floor points in row order (as pixels are traced) towards a low
/// sun shining in through the window.
std::vector<Ray> sun_rays() {
    const Vec3 to_sun = normalize(Vec3(0.1f, 1.0f, 0.45f));
    std::vector<Ray> rays;
    for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 50; ++i)
            rays.push_back(Ray{{0.1f + 0.2f * float(i), 0.1f + 0.2f * float(j), 1e-3f}, to_sun});
    return rays;
}

/// Restores automatic SIMD path selection when a test ends.
struct SimdGuard {
    ~SimdGuard() { force_simd_path(best_simd_path()); }
};

/// Closest hits and occlusion of `rays` against brute force over every primitive.
struct BruteForceTally {
    int wrong_hit = 0, wrong_occluded = 0, hits = 0, free = 0;
};

/// `rel_t` 0: the traversal's t (and the ray's shortened tmax) equal brute force's bit
/// for bit; otherwise t within that fraction of it.
BruteForceTally against_brute_force(const Accelerator& accel, const std::vector<Ray>& rays, float rel_t) {
    BruteForceTally n;
    for (const Ray& r : rays) {
        Ray a = r, b = r;
        Hit ha, hb;
        const bool fa = accel.intersect(a, ha), fb = accel.intersect_brute_force(b, hb);
        const bool t_differs =
            rel_t == 0.0f ? (ha.t != hb.t || a.tmax != ha.t) : std::fabs(ha.t - hb.t) > rel_t * hb.t;
        n.wrong_hit += int(fa != fb || (fa && t_differs));
        n.wrong_occluded += int(accel.occluded(r) != fb);
        n.hits += int(fb);
        n.free += int(!fb);
    }
    return n;
}

}  // namespace

TEST_CASE("occlusion cache and child order: brute-force answers on a generated room on every SIMD path") {
    SimdGuard guard;
    const Scene scene = build_scene(room());
    const std::vector<Ray> rays = sun_rays();
    for (OcclusionOrder order : {OcclusionOrder::slot, OcclusionOrder::far_first}) {
        AcceleratorOptions o;
        o.occlusion_order = order;
        const Accelerator accel(scene, o);
        CHECK(accel.occlusion_far_first() == (order == OcclusionOrder::far_first));
        for (SimdPath path : runnable_simd_paths()) {
            force_simd_path(path);
            OcclusionCache cache;
            int wrong = 0, occluded = 0, served = 0;
            for (const Ray& r : rays) {
                Ray b = r;
                Hit h;
                const bool want = accel.intersect_brute_force(b, h);
                const OcclusionCache before = cache;
                const bool cached = accel.occluded(r, cache);
                wrong += int(accel.occluded(r) != want) + int(cached != want);
                occluded += int(want);
                // The cache served the ray when it kept its block and the ray is blocked.
                served += int(cached && before.owner == &accel && before.block == cache.block);
            }
            CHECK(wrong == 0);
            // Some rays leave through the window, most are stopped, mostly by the block
            // that stopped the ray before.
            CHECK(occluded > int(rays.size()) / 2);
            CHECK(occluded < int(rays.size()));
            CHECK(served > occluded / 2);
        }
    }
}

TEST_CASE("occlusion cache: another accelerator's or an out-of-range entry is ignored") {
    const Scene scene = build_scene(room());
    const Accelerator a(scene), b(scene);
    const Ray up{{5, 4, 1}, {0, 0, 1}};
    OcclusionCache cache;
    REQUIRE(a.occluded(up, cache));
    CHECK(cache.owner == &a);
    // b ignores a's entry, answers right and takes the cache over.
    CHECK(b.occluded(up, cache));
    CHECK(cache.owner == &b);
    // An entry past the blocks is not read; the ray through the window is free.
    cache.block = 0xFFFFFFF0u;
    const Ray out{{4.5f, 7, 1.7f}, {0, 1, 0}};
    CHECK_FALSE(b.occluded(out, cache));
    CHECK(cache.block == 0xFFFFFFF0u);  // a free ray leaves the cache as it was
}

TEST_CASE("occlusion order: automatic picks farthest first in a room and slot order on open ground") {
    const Accelerator room_accel(build_scene(room()));
    CHECK(room_accel.occlusion_far_first());
    // Nothing stops the sample rays of a flat grid: sorting would buy nothing.
    SceneDesc d;
    d.materials.push_back(MaterialDesc{});
    d.meshes.push_back(unit_grid(32, 0.0f, 0));
    const Accelerator ground_accel(build_scene(d));
    CHECK_FALSE(ground_accel.occlusion_far_first());
}

TEST_CASE(
    "random rays in a room: closest and any hit agree with brute force in both child orders on every SIMD "
    "path") {
    // Rays from inside and around the room in every direction, every other one with a short
    // tmax: node steps with 0, 1, 2 and more hit children, culled stack entries, and rays
    // that empty the stack (the AVX-512 steps' sentinel) without a hit.
    SimdGuard guard;
    const Scene scene = build_scene(room());
    for (OcclusionOrder order : {OcclusionOrder::slot, OcclusionOrder::far_first}) {
        AcceleratorOptions o;
        o.occlusion_order = order;
        const Accelerator accel(scene, o);
        // make_random_rays spreads origins over its box grown by half its size on every
        // side: over the room's bounds for the inner half of them.
        const Bounds3 b = accel.bounds();
        const Vec3 quarter = b.extent() * 0.25f;
        std::vector<Ray> rays =
            make_random_rays({b.lo + quarter, b.hi - quarter}, 6000 / kSanitizerDivisor, 907);
        for (size_t i = 0; i < rays.size(); i += 2) rays[i].tmax = 0.2f + 0.002f * float(i % 1000);
        for (SimdPath path : runnable_simd_paths()) {
            force_simd_path(path);
            INFO("far first ", int(order == OcclusionOrder::far_first), " path ",
                 std::string(simd_path_name(path)));
            const BruteForceTally tally = against_brute_force(accel, rays, 0.0f);
            CHECK(tally.wrong_hit == 0);
            CHECK(tally.wrong_occluded == 0);
            // Both answers are common, so a traversal that lost or invented hits would show.
            CHECK(tally.hits > int(rays.size()) / 8);
            CHECK(tally.free > int(rays.size()) / 8);
        }
    }
}

TEST_CASE(
    "rays along axes and faces and at corners agree with brute force near and far from the origin on every "
    "SIMD path") {
    // The cases a box test gets wrong first (zero direction components, origins on slab
    // planes, large and small coordinates); a lost box would lose a hit here. Origins on
    // the walls' and boxes' planes, directions along the axes (other components +0 or -0),
    // in the axis planes (one component zero), aimed at box corners, and random ones, in
    // the room as built, moved far away, and scaled up and down.
    SimdGuard guard;
    struct Frame {
        float scale;
        Vec3 offset;
    };
    for (const Frame f : {Frame{1.0f, {}}, Frame{1.0f, {3e5f, -2e6f, 1e6f}}, Frame{1e-6f, {}},
                          Frame{1e6f, {5e7f, 0, -3e7f}}}) {
        SceneDesc d = room();
        for (TriangleMesh& m : d.meshes)
            for (Vec3& p : m.positions) p = p * f.scale + f.offset;
        const Scene scene = build_scene(d);
        const Accelerator accel(scene, AcceleratorOptions{});
        auto at = [&](float x, float y, float z) { return Vec3(x, y, z) * f.scale + f.offset; };
        std::vector<Ray> rays;
        const float planes_x[] = {0.0f, 0.2f, 0.3f, 5.0f, 10.0f}, planes_y[] = {0.0f, 0.2f, 0.3f, 4.0f, 8.0f},
                    planes_z[] = {0.0f, 0.1f, 1.0f, 3.0f};
        std::vector<Vec3> dirs;
        for (int a = 0; a < 3; ++a)
            for (float s : {-1.0f, 1.0f}) {
                Vec3 v(0.0f, -0.0f, 0.0f);
                v[a] = s;
                dirs.push_back(v);
                Vec3 w(-0.0f, 0.0f, -0.0f);
                w[a] = s * 0.6f;
                w[(a + 1) % 3] = 0.8f;
                dirs.push_back(w);
            }
        dirs.push_back(normalize(Vec3(0.3f, -0.5f, 0.2f)));
        for (float x : planes_x)
            for (float y : planes_y)
                for (float z : planes_z) {
                    const Vec3 o = at(x, y, z);
                    for (const Vec3& v : dirs) rays.push_back(Ray{o, v});
                    // At the corners of a small box (i = 3, j = 2) and of the window.
                    for (const Vec3 corner :
                         {at(1.4f, 0.96f, 0.1f), at(1.3f, 0.96f, 0.0f), at(3.0f, 8.0f, 2.5f)})
                        if (!(corner == o)) rays.push_back(Ray{o, corner - o});
                }
        for (size_t i = 0; i < rays.size(); i += 3) rays[i].tmax = 2.0f * f.scale;
        // Abutting boxes share edges and planes, where two triangles' hit distances (and one
        // triangle's on different SIMD paths) can differ in the last bits: the distances
        // are compared to a millionth, hit or miss exactly.
        for (SimdPath path : runnable_simd_paths()) {
            force_simd_path(path);
            INFO("scale ", f.scale, " path ", std::string(simd_path_name(path)));
            const BruteForceTally tally = against_brute_force(accel, rays, 1e-6f);
            CHECK(tally.wrong_hit == 0);
            CHECK(tally.wrong_occluded == 0);
            CHECK(tally.hits > int(rays.size()) / 8);
            CHECK(tally.free > 0);
        }
    }
}
