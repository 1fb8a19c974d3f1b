// The FMA box test of the AVX2 and AVX-512 node steps (Bvh8RayAvx) against an exact
// slab test: it may hit more boxes, never fewer, on adversarial rays (zero and tiny
// direction components, origins on box planes, rays aimed at box edges and corners,
// huge and tiny coordinates).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "accel/simd_path.h"
#include "accel/traverse_wide.h"
#include "sanitizer_build.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// The exact slab test of one box, in long double: the coordinates of a case lie on one
/// grid of at most 2^40 steps, so plane - origin is exact there, and a correctly rounded
/// quotient keeps the order of the exact ones, so this says "hit" whenever the exact test
/// does. A zero direction component bounds nothing when the origin lies in the slab.
bool exact_slab_hit(const float lo[3], const float hi[3], const Ray& ray, long double& entry) {
    long double t0 = ray.tmin, t1 = ray.tmax;
    for (int a = 0; a < 3; ++a) {
        const long double o = ray.origin[a], d = ray.dir[a];
        if (d == 0) {
            if (o < lo[a] || o > hi[a]) return false;
            continue;
        }
        long double n = (lo[a] - o) / d, f = (hi[a] - o) / d;
        if (d < 0) std::swap(n, f);
        t0 = std::max(t0, n);
        t1 = std::min(t1, f);
    }
    entry = t0;
    return t0 <= t1;
}

/// A float on the case's grid: k steps of `step` from `base`.
float on_grid(float base, float step, long k) { return base + step * float(k); }

struct Counts {
    long boxes = 0, exact_hits = 0, misses = 0, far_entries = 0;
    long tiny_axes = 0, off_axes = 0, zero_components = 0, on_plane = 0;
};

/// One node of eight grid boxes and one ray of the given kind; every box the exact test
/// hits must be hit, with an entry distance at most a few roundings above the exact one.
__attribute__((target("avx2,fma"))) void check_case(std::mt19937& rng, int kind, Counts& n) {
    // The grid: steps of 2^s around a base of up to 2^b (huge coordinates: b large, so
    // nearby values differ in their last bits; tiny ones: s very negative).
    std::uniform_int_distribution<int> scale(-60, 30), cell(-40, 40);
    const int s = scale(rng);
    const float step = std::ldexp(1.0f, s);
    const float base = rng() % 2 ? 0.0f : std::ldexp(float(int(rng() % 1024) - 512), s + 16 + int(rng() % 8));
    auto coord = [&] { return on_grid(base, step, cell(rng)); };
    Bvh8Node node{};
    float extent = 0.0f;
    float lo[8][3], hi[8][3];
    for (int c = 0; c < 8; ++c) {
        for (int a = 0; a < 3; ++a) {
            float x = coord(), y = coord();
            if (rng() % 6 == 0) y = x;  // a flat box
            lo[c][a] = std::min(x, y), hi[c][a] = std::max(x, y);
            extent = std::max({extent, std::fabs(lo[c][a]), std::fabs(hi[c][a])});
        }
        node.lo_x[c] = lo[c][0], node.lo_y[c] = lo[c][1], node.lo_z[c] = lo[c][2];
        node.hi_x[c] = hi[c][0], node.hi_y[c] = hi[c][1], node.hi_z[c] = hi[c][2];
        node.child[c] = uint32_t(c) * 256;
    }
    // The ray: origin on the grid (often on a box plane), direction by kind.
    Ray ray{Vec3(coord(), coord(), coord()), Vec3(0, 0, 1)};
    const int target = int(rng() % 8);
    if (rng() % 3 == 0)
        ray.origin[int(rng() % 3)] = rng() % 2 ? lo[target][rng() % 3] : hi[target][rng() % 3];
    for (int a = 0; a < 3; ++a) {
        for (int c = 0; c < 8; ++c) n.on_plane += ray.origin[a] == lo[c][a] || ray.origin[a] == hi[c][a];
    }
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    switch (kind) {
        case 0:  // random
            ray.dir = Vec3(u(rng), u(rng), u(rng));
            break;
        case 1:  // along an axis, the other components +0 or -0
        {
            const int a = int(rng() % 3);
            ray.dir = Vec3(rng() % 2 ? -0.0f : 0.0f, rng() % 2 ? -0.0f : 0.0f, rng() % 2 ? -0.0f : 0.0f);
            ray.dir[a] = rng() % 2 ? -1.0f : 1.0f;
            break;
        }
        case 2:  // in a plane: one component zero (grazing a face when the origin is on it)
            ray.dir = Vec3(u(rng), u(rng), u(rng));
            ray.dir[int(rng() % 3)] = rng() % 2 ? -0.0f : 0.0f;
            break;
        case 3:  // at a corner or an edge point of a box (rounded direction)
        {
            Vec3 p(rng() % 2 ? lo[target][0] : hi[target][0], rng() % 2 ? lo[target][1] : hi[target][1],
                   rng() % 2 ? lo[target][2] : hi[target][2]);
            if (rng() % 2) p[int(rng() % 3)] = coord();  // on an edge's line
            ray.dir = p - ray.origin;
            break;
        }
        default:  // tiny components (subnormal to 2^-70) beside a regular one
            ray.dir = Vec3(u(rng), u(rng), u(rng));
            for (int a = 0; a < 3; ++a)
                if (rng() % 2) ray.dir[a] = std::ldexp(u(rng), -70 - int(rng() % 80));
            break;
    }
    if (ray.dir == Vec3(0, 0, 0)) ray.dir = Vec3(0, 0, -1);
    for (int a = 0; a < 3; ++a) n.zero_components += ray.dir[a] == 0.0f;
    if (rng() % 3 == 0) ray.tmax = std::ldexp(1.0f, s + int(rng() % 12));
    if (rng() % 4 == 0) ray.tmin = std::ldexp(1.0f, s - int(rng() % 12));
    const BvhRay r(ray);
    const Bvh8RayAvx avx(r, extent);
    for (int a = 0; a < 3; ++a) {
        const float inv = _mm256_cvtss_f32(avx.inv[a]);
        n.tiny_axes += std::fabs(inv) == Bvh8RayAvx::kFmaBoxTinyInv;
        n.off_axes += std::fabs(inv) == 0x1p-100f;
    }
    alignas(32) float t[8];
    const int mask = intersect_bvh8_avx(node, avx, r.tmin, r.tmax * kRobustFarScale, t);
    for (int c = 0; c < 8; ++c) {
        ++n.boxes;
        long double entry = 0;
        if (!exact_slab_hit(lo[c], hi[c], ray, entry)) continue;
        ++n.exact_hits;
        if (!(mask & (1 << c))) {
            ++n.misses;
            continue;
        }
        if (static_cast<long double>(t[c]) > entry * (1 + 0x1p-21L) + 0x1p-120L) ++n.far_entries;
    }
}

}  // namespace

TEST_CASE("FMA box test: never a miss where the exact slab test hits [needs AVX2]" *
          doctest::skip(!cpu_has_avx2())) {
    std::mt19937 rng(2026);
    Counts n;
    const int cases = 400000 / kSanitizerDivisor;
    for (int i = 0; i < cases; ++i) check_case(rng, i % 5, n);
    MESSAGE("boxes " << n.boxes << ", exact hits " << n.exact_hits << ", replaced inverses " << n.tiny_axes
                     << ", axes switched off " << n.off_axes << ", zero components " << n.zero_components
                     << ", origin coordinates on a plane " << n.on_plane);
    CHECK(n.misses == 0);
    CHECK(n.far_entries == 0);
    // Every kind of case occurred, so a test that lost them would show.
    CHECK(n.exact_hits > n.boxes / 20);
    CHECK(n.tiny_axes > cases / 10);
    CHECK(n.zero_components > cases / 10);
    CHECK(n.on_plane > cases / 10);
    CHECK(n.off_axes > 0);
}
