#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "scene/accelerator.h"
#include "accel/packet.h"
#include "io/mesh_triangles.h"
#include "scene/mesh_scene.h"
#include "mesh_fixtures.h"
#include "render/film.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Restores the automatic SIMD path when a test ends.
struct SimdPathGuard {
    ~SimdPathGuard() { clear_forced_simd_path(); }
};

/// An icosphere, a grid of small spheres in front of it, and a box.
Scene mixed_scene() {
    const TriangleMesh ico = make_icosphere(3);
    Scene s;
    s.triangles.positions = ico.positions;
    s.triangles.indices = ico.indices;
    s.triangles.material.assign(ico.indices.size() / 3, 0);
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j)
            s.spheres.push_back(Sphere{Vec3(-1.0f + 0.5f * float(i), -1.0f + 0.5f * float(j), 1.3f), 0.12f});
    s.boxes.push_back(Box{Bounds3{Vec3(-2.0f, -2.0f, -2.5f), Vec3(2.0f, 2.0f, -2.2f)}, 0});
    return s;
}

/// Counts how packet answers compare with single rays (bitwise t, u, v and prim; ties apart).
struct Agreement {
    int rays = 0, hits = 0, ties = 0, mismatches = 0, inactive_touched = 0;
};

void compare_packet(const Accelerator& acc, RayPacket packet, Agreement& a) {
    const RayPacket before = packet;
    HitPacket hp;
    acc.intersect_packet(packet, hp);
    for (int i = 0; i < kPacketSize; ++i) {
        if (!(before.active >> i & 1)) {
            if (hp.prim[i] != kNoPrim) ++a.inactive_touched;
            continue;
        }
        ++a.rays;
        Ray r = before.ray(i);
        Hit h;
        const bool hit = acc.intersect(r, h);
        a.hits += hit;
        const Hit ph = hp.hit(i);
        if (hit != ph.hit()) {
            if (a.mismatches < 3)
                MESSAGE("lane " << i << " single " << hit << " t " << h.t << " packet t " << ph.t << " prim "
                                << ph.prim);
            ++a.mismatches;
            continue;
        }
        if (!hit) continue;
        if (std::bit_cast<uint32_t>(h.t) != std::bit_cast<uint32_t>(ph.t) || packet.tmax[i] != ph.t) {
            ++a.mismatches;
        } else if (h.prim != ph.prim) {
            ++a.ties;  // another primitive at exactly the same distance
        } else if (std::bit_cast<uint32_t>(h.u) != std::bit_cast<uint32_t>(ph.u) ||
                   std::bit_cast<uint32_t>(h.v) != std::bit_cast<uint32_t>(ph.v)) {
            ++a.mismatches;
        }
    }
}

/// 4x4 tiles of pinhole rays over an n x n image looking at the origin from `eye`.
std::vector<RayPacket> camera_packets(Vec3 eye, int n, float fov_tan) {
    const Vec3 fwd = normalize(-eye), right = normalize(cross(fwd, Vec3(0, 1, 0))), up = cross(right, fwd);
    std::vector<RayPacket> out;
    for (int ty = 0; ty < n; ty += 4)
        for (int tx = 0; tx < n; tx += 4) {
            RayPacket p;
            for (int i = 0; i < kPacketSize; ++i) {
                const float x = float(tx + i % 4) + 0.5f, y = float(ty + i / 4) + 0.5f;
                const float sx = (2.0f * x / float(n) - 1.0f) * fov_tan,
                            sy = (1.0f - 2.0f * y / float(n)) * fov_tan;
                p.set(i, Ray{eye, normalize(fwd + right * sx + up * sy)});
            }
            out.push_back(p);
        }
    return out;
}

AcceleratorOptions with_layout(BvhLayout layout) {
    AcceleratorOptions o;
    o.layout = layout;
    return o;
}

}  // namespace

namespace {

/// Coherent camera tiles traced as packets on `path` agree with single rays.
void check_camera_tiles(SimdPath path) {
    SimdPathGuard guard;
    const Scene scene = mixed_scene();
    const int n = kSanitized ? 32 : 96;
    for (BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs}) {
        const Accelerator acc(scene, with_layout(layout));
        force_simd_path(path);
        const std::string name = std::string(simd_path_name(path)) + " " + bvh_layout_name(layout);
        CAPTURE(name);
        Agreement a;
        for (const Vec3& eye : {Vec3(0.3f, 0.2f, 4.0f), Vec3(-3.0f, 2.0f, -3.0f), Vec3(0.0f, 0.0f, 5.0f)})
            for (const RayPacket& p : camera_packets(eye, n, 0.6f)) compare_packet(acc, p, a);
        CHECK(a.mismatches == 0);
        CHECK(a.ties <= a.rays / 1000);
        CHECK(a.hits > a.rays / 4);
    }
}

}  // namespace

// One test case per SIMD path, so that a CPU without AVX2 or AVX-512 shows those paths as skipped.
TEST_CASE("packets agree with single rays: coherent camera tiles, on the SSE2 path") {
    check_camera_tiles(SimdPath::sse2);
}

TEST_CASE("packets agree with single rays: coherent camera tiles, on the AVX2 path [needs AVX2]" *
          doctest::skip(!cpu_has_avx2())) {
    check_camera_tiles(SimdPath::avx2);
}

TEST_CASE("packets agree with single rays: coherent camera tiles, on the AVX-512 path [needs AVX-512]" *
          doctest::skip(!cpu_has_avx512())) {
    check_camera_tiles(SimdPath::avx512);
}

TEST_CASE("packets agree with single rays: incoherent rays, tmax limits, inactive lanes, axis rays") {
    SimdPathGuard guard;
    const Scene scene = mixed_scene();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const int packets = kSanitized ? 150 : 2000;
    for (BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs})
        for (SimdPath path : runnable_simd_paths()) {
            const Accelerator acc(scene, with_layout(layout));
            force_simd_path(path);
            const std::string name = std::string(simd_path_name(path)) + " " + bvh_layout_name(layout);
            CAPTURE(name);
            Agreement a;
            for (int k = 0; k < packets; ++k) {
                RayPacket p;
                const int kind = k % 4;
                // Same-octant bundles (kernel path) with jittered origins, or fully random rays (fallback).
                const Vec3 base_o(3.0f * u(rng), 3.0f * u(rng), 4.0f);
                // kind 0: non-negative x and y, so the +0 components of the axis rays share the octant.
                const float ux = kind == 0 ? std::fabs(u(rng)) : u(rng),
                            uy = kind == 0 ? std::fabs(u(rng)) : u(rng);
                const Vec3 base_d = normalize(Vec3(0.3f * ux, 0.3f * uy, -1.0f));
                const uint32_t active = kind == 3 ? uint32_t(rng()) & 0xFFFFu : 0xFFFFu;
                for (int i = 0; i < kPacketSize; ++i) {
                    Ray r;
                    if (kind == 1) {
                        r = Ray{Vec3(3.0f * u(rng), 3.0f * u(rng), 3.0f * u(rng)),
                                Vec3(u(rng), u(rng), u(rng))};
                    } else {
                        r = Ray{base_o + Vec3(0.05f * u(rng), 0.05f * u(rng), 0.0f),
                                base_d + Vec3(0.02f * std::fabs(u(rng)), 0.02f * std::fabs(u(rng)), 0.0f)};
                    }
                    if (kind == 2) r.tmax = 3.0f + 2.0f * u(rng);  // some end before the geometry
                    if (kind == 0 && i % 5 == 0) r.dir = Vec3(0.0f, 0.0f, -1.0f);  // zero components
                    if (kind == 0 && i % 7 == 0) r.tmin = 3.0f;
                    if (active >> i & 1) p.set(i, r);
                }
                p.active = active;
                compare_packet(acc, p, a);
            }
            CHECK(a.mismatches == 0);
            CHECK(a.inactive_touched == 0);
            CHECK(a.ties <= a.rays / 1000);
            CHECK(a.hits > a.rays / 10);
        }
}

TEST_CASE("packets agree with single rays that run inside box planes (zero direction components)") {
    // A 16 x 16 grid of quads in z = 0 over [-1, 1]^2: many leaf boxes have a face on a
    // grid line. Each packet starts on a grid line x = k / 8 and mixes rays with a
    // signed-zero x direction (inverse +-inf, 0 * inf = NaN in that slab) with rays
    // slightly tilted the same way, so the packet's frustum meets 0 * inf at its corners.
    SimdPathGuard guard;
    Scene scene;
    const int n = 16;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x)
            scene.triangles.positions.push_back(
                Vec3(-1.0f + 2.0f * float(x) / n, -1.0f + 2.0f * float(y) / n, 0.0f));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const uint32_t a = uint32_t(y * (n + 1) + x), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            scene.triangles.indices.insert(scene.triangles.indices.end(), {a, b, d, a, d, c});
        }
    scene.triangles.material.assign(scene.triangles.indices.size() / 3, 0);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs})
        for (SimdPath path : runnable_simd_paths()) {
            const Accelerator acc(scene, with_layout(layout));
            force_simd_path(path);
            const std::string name = std::string(simd_path_name(path)) + " " + bvh_layout_name(layout);
            CAPTURE(name);
            Agreement a;
            for (int k = -8; k <= 8; ++k)
                for (const float sign : {-1.0f, 1.0f})
                    for (int rep = 0; rep < 8; ++rep) {
                        RayPacket p;
                        const float y0 = -0.9f + 1.8f * u(rng);
                        for (int i = 0; i < kPacketSize; ++i) {
                            const float dx = i % 2 ? sign * 0.0f : sign * 1e-3f * float(i);
                            p.set(i, Ray{Vec3(float(k) / 8.0f, y0 + 0.01f * float(i), 1.0f),
                                         Vec3(dx, 0.05f * u(rng), -1.0f)});
                        }
                        compare_packet(acc, p, a);
                    }
            CHECK(a.mismatches == 0);
            CHECK(a.hits > a.rays / 2);
        }
}

TEST_CASE(
    "packets on a 70k-triangle scan-like mesh and on the pairs layout (ray-by-ray fallback) agree "
    "with single rays") {
    SimdPathGuard guard;
    // Big, bumpy, with holes and slivers: deep trees and ragged packet frusta, as on a real scan.
    const TriangleMesh mesh = make_scan_mesh_70k();
    const Scene scene = scene_from_mesh(mesh);
    AcceleratorOptions pairs;
    pairs.layout = BvhLayout::pairs;
    const Accelerator wide(scene), pair(scene, pairs);
    const Vec3 c = wide.bounds().center();
    const float r = length(wide.bounds().extent());
    const int n = kSanitized ? 24 : 128;
    for (SimdPath path : runnable_simd_paths()) {
        force_simd_path(path);
        const std::string name = simd_path_name(path);
        CAPTURE(name);
        Agreement a, b;
        for (RayPacket p : camera_packets(Vec3(0.4f, 0.3f, 1.0f) * (2.0f * r), n, 0.5f)) {
            for (int i = 0; i < kPacketSize; ++i) p.org[0][i] += c.x, p.org[1][i] += c.y, p.org[2][i] += c.z;
            compare_packet(wide, p, a);
            compare_packet(pair, p, b);
        }
        CHECK(a.mismatches == 0);
        CHECK(b.mismatches == 0);
        CHECK(a.ties <= a.rays / 1000);
        CHECK(a.hits > a.rays / 20);
    }
}

TEST_CASE("SIMD path names and forcing a path") {
    CHECK(std::strcmp(simd_path_name(SimdPath::avx512), "avx512") == 0);
    CHECK(std::strcmp(simd_path_name(SimdPath::avx2), "avx2") == 0);
    CHECK(std::strcmp(simd_path_name(SimdPath::sse2), "sse2") == 0);
    // One path for single rays and packets: forcing one and clearing it again.
    const SimdPath automatic = active_simd_path();
    force_simd_path(SimdPath::sse2);
    CHECK(active_simd_path() == SimdPath::sse2);
    clear_forced_simd_path();
    CHECK(active_simd_path() == automatic);
}

namespace {

bool same_film(const Film& a, const Film& b) {
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            if (a.count(x, y) != b.count(x, y) || !(a.sum(x, y) == b.sum(x, y)) ||
                !(a.sum_sq(x, y) == b.sum_sq(x, y)))
                return false;
    return true;
}

/// Renders `desc` at w x h with packets on and off and compares the films bit for bit.
void check_packets_keep_image(SceneDesc desc, int w, int h, int spp) {
    desc.render.width = w;
    desc.render.height = h;
    desc.render.spp = spp;
    desc.render.packets = true;
    const Scene scene = build_scene(desc);
    desc.render.packets = false;  // what --no-packets sets
    const Scene single_rays = build_scene(desc);
    Film with(w, h), without(w, h), pass_with(w, h), pass_without(w, h);
    RenderOptions o;
    o.threads = 2;
    render_image(scene, with, o);
    render_pass(scene, pass_with, 0, spp, 2, nullptr);
    render_image(single_rays, without, o);
    render_pass(single_rays, pass_without, 0, spp, 2, nullptr);
    CHECK(same_film(with, without));
    CHECK(same_film(pass_with, pass_without));
    CHECK(same_film(with, pass_with));
}

}  // namespace

TEST_CASE("renders with packets on and off are bit-identical (cornell box, default scene, showcase)") {
    check_packets_keep_image(parse_scene_file(SAHARA_SOURCE_DIR "/scenes/cornell-box.json"), 37, 29,
                             kSanitized ? 1 : 3);
    check_packets_keep_image(default_scene(), 30, 22, kSanitized ? 1 : 4);
    check_packets_keep_image(parse_scene_file(SAHARA_SOURCE_DIR "/scenes/showcase.json"), 26, 18, 1);
}
