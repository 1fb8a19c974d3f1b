// The SIMD kernels of the wide8 layout against their scalar references, bit for
// bit: the node box steps (SSE halves, AVX2, AVX-512) against the exact slab test,
// and the four- and eight-lane triangle tests against the watertight test.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "accel/bvh4_leaf.h"
#include "accel/simd_path.h"
#include "accel/traverse_wide.h"
#include "mesh_fixtures.h"
#include "test_data.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A ray for the box-test cases: integer origin (often exactly on a slab plane),
/// direction components zeroed (+0 or -0) a third of the time, sometimes a short tmax.
Ray random_slab_test_ray(std::mt19937& rng, std::uniform_int_distribution<int>& coord,
                         std::uniform_real_distribution<float>& u) {
    // Braced initialisation: the draws happen left to right.
    Ray ray{Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))), Vec3(u(rng), u(rng), u(rng))};
    for (int a = 0; a < 3; ++a)
        if (rng() % 3 == 0) ray.dir[a] = (rng() % 2) ? -0.0f : 0.0f;
    if (rng() % 4 == 0) ray.tmax = std::fabs(u(rng));
    return ray;
}

}  // namespace

TEST_CASE("BVH8 box test in SSE halves matches the single-node test") {
    std::mt19937 rng(32);
    std::uniform_int_distribution<int> coord(-2, 2);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    int bad = 0, hits = 0;
    for (int i = 0; i < 50000 / kSanitizerDivisor; ++i) {
        BvhNode child[8];
        Bvh8Node n{};
        for (int c = 0; c < 8; ++c) {
            Bounds3 b = Bounds3::of_point(Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))));
            b.extend(Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))));
            if (rng() % 50 == 0) b = Bounds3{};
            child[c].set_box(b);
            n.lo_x[c] = b.lo.x, n.lo_y[c] = b.lo.y, n.lo_z[c] = b.lo.z;
            n.hi_x[c] = b.hi.x, n.hi_y[c] = b.hi.y, n.hi_z[c] = b.hi.z;
        }
        const BvhRay r(random_slab_test_ray(rng, coord, u));
        alignas(32) float t_sse[8];
        const int mask_sse = WideRay<8, false>(r).test(n, r.tmin, r.tmax * kRobustFarScale, t_sse);
        for (int c = 0; c < 8; ++c) {
            float t = 0.0f;
            const bool hit = intersect_bvh_node(child[c], r, t);
            hits += hit;
            if (hit != bool(mask_sse & (1 << c))) ++bad;
            if (hit && t != t_sse[c]) ++bad;
        }
    }
    CHECK(bad == 0);
    CHECK(hits > 0);
}

namespace {

/// The BVH8 AVX2 node step (and with `avx512` the AVX-512 ones, compressed in slot
/// order, and the paired step) against the exact slab test, on random nodes and rays.
void check_bvh8_node_steps(bool avx512) {
    std::mt19937 rng(33);
    std::uniform_int_distribution<int> coord(-2, 2);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    int bad = 0, multi = 0, on_far_plane = 0, tighter = 0, paired_both = 0;
    // The previous iteration's node: the paired step's `a`.
    Bvh8Node prev{};
    for (int i = 0; i < 50000 / kSanitizerDivisor; ++i) {
        Bvh8Node n{};
        BvhNode single[8];
        for (int c = 0; c < 8; ++c) {
            Bounds3 b = Bounds3::of_point(Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))));
            b.extend(Vec3(float(coord(rng)), float(coord(rng)), float(coord(rng))));
            if (rng() % 8 == 0) b = Bounds3{};  // empty slot
            single[c].set_box(b);
            n.lo_x[c] = b.lo.x, n.lo_y[c] = b.lo.y, n.lo_z[c] = b.lo.z;
            n.hi_x[c] = b.hi.x, n.hi_y[c] = b.hi.y, n.hi_z[c] = b.hi.z;
            n.child[c] = b.empty() ? kNoNode : uint32_t(rng());
        }
        const BvhRay r(random_slab_test_ray(rng, coord, u));
        const float tmax_far = r.tmax * kRobustFarScale;
        // Reference: the slab distances of intersect_bvh_node, every NaN (a zero direction
        // component, the origin on the plane) dropped on its own, and the documented extra
        // hit for an exit distance of +0 (the origin on the far plane of a positive direction).
        int mask = 0;
        float entry[8];
        for (int c = 0; c < 8; ++c) {
            const float lo[3] = {n.lo_x[c], n.lo_y[c], n.lo_z[c]}, hi[3] = {n.hi_x[c], n.hi_y[c], n.hi_z[c]};
            float t0 = r.tmin, t1 = tmax_far;
            bool exit_plus_zero = false;
            for (int a = 0; a < 3; ++a) {
                const float tn = ((r.neg[a] ? hi[a] : lo[a]) - r.org[a]) * r.inv_dir[a];
                const float tf = ((r.neg[a] ? lo[a] : hi[a]) - r.org[a]) * r.inv_far[a];
                if (!std::isnan(tn)) t0 = std::max(t0, tn);
                if (!std::isnan(tf)) t1 = std::min(t1, tf);
                exit_plus_zero |= tf == 0.0f && !std::signbit(tf);
            }
            entry[c] = t0;
            if (t0 <= t1)
                mask |= 1 << c;
            else if (exit_plus_zero)
                mask |= 1 << c, ++on_far_plane;
            // The scalar test drops a whole pair around a NaN, so it can hit children the
            // exact test misses (counted, not an error), never the other way round.
            float t_single = 0.0f;
            const bool hit_single = intersect_bvh_node(single[c], r, t_single);
            if (t0 <= t1 && !hit_single) ++bad;
            tighter += hit_single && !(mask & (1 << c));
        }
        multi += __builtin_popcount(unsigned(mask)) > 1;
        const WideRay<8, true> rw(r);
        alignas(32) float t_avx[8];
        const int mask_avx = rw.test(n, r.tmin, tmax_far, t_avx);
        if (mask_avx != mask) ++bad;
        for (int c = 0; c < 8; ++c)
            if ((mask & (1 << c)) && t_avx[c] != entry[c]) ++bad;
        if (!avx512) continue;
        alignas(32) float t[8];
        alignas(32) uint32_t child[8];
        const Bvh8HitChildren h = intersect_bvh8_compress_avx512(n, rw.avx, r.tmin, tmax_far, child, t);
        if (int(h.mask) != mask) ++bad;
        // The any-hit form: the first hit in registers, the others as stack entries (the
        // reference in the low word; the high word is garbage).
        uint64_t entries[8];
        const Bvh8HitChildren ha = intersect_bvh8_entries_avx512(n, rw.avx, r.tmin, tmax_far, entries);
        if (ha.mask != h.mask || ha.ref0 != h.ref0) ++bad;
        for (int i = 1; i < __builtin_popcount(h.mask); ++i)
            if (uint32_t(entries[i - 1]) != child[i]) ++bad;
        int i_hit = 0;
        std::vector<std::array<uint32_t, 2>> hits;  // child, entry bits (slot order)
        for (int c = 0; c < 8; ++c) {
            if (!(mask & (1 << c))) continue;
            if (child[i_hit] != n.child[c] || t[i_hit] != entry[c]) ++bad;
            if (i_hit == 0 && (h.ref0 != n.child[c] || h.t0 != entry[c])) ++bad;
            hits.push_back({n.child[c], std::bit_cast<uint32_t>(entry[c])});
            ++i_hit;
        }
        // The paired step over the previous node (tested with this ray) and this one: the
        // hit children of both, the previous node's first, all of them with their distances
        // as stack entries (reference low, distance high).
        if (i > 0) {
            std::vector<std::array<uint32_t, 2>> expected;
            alignas(32) float tp[8];
            const int mask_prev = rw.test(prev, r.tmin, tmax_far, tp);
            for (int c = 0; c < 8; ++c)
                if (mask_prev & (1 << c)) expected.push_back({prev.child[c], std::bit_cast<uint32_t>(tp[c])});
            paired_both += !expected.empty() && !hits.empty();
            expected.insert(expected.end(), hits.begin(), hits.end());
            alignas(32) uint64_t pe[16];
            const Bvh8HitChildren hp = intersect_bvh8_pair_avx512(prev, n, rw.avx, r.tmin, tmax_far, pe);
            if (hp.mask != expected.size()) {
                ++bad;
            } else if (hp.mask > 0) {
                if (hp.ref0 != expected[0][0] || std::bit_cast<uint32_t>(hp.t0) != expected[0][1]) ++bad;
                for (size_t k = 0; k < hp.mask; ++k)
                    if (pe[k] != (uint64_t(expected[k][1]) << 32 | expected[k][0])) ++bad;
            }
        }
        prev = n;
    }
    CHECK(bad == 0);
    if (avx512) CHECK(paired_both > 0);
    CHECK(multi > 0);
    CHECK(on_far_plane > 0);
    CHECK(tighter > 0);
    MESSAGE("hit only for an origin on the far plane: " << on_far_plane
                                                        << "; hit by the scalar test only: " << tighter);
}

}  // namespace

TEST_CASE("BVH8 AVX2 node step: the exact slab test's hits [needs AVX2]" * doctest::skip(!cpu_has_avx2())) {
    check_bvh8_node_steps(false);
}

TEST_CASE("BVH8 AVX-512 node steps: the exact slab test's hits, compressed in slot order [needs AVX-512]" *
          doctest::skip(!cpu_has_avx512())) {
    check_bvh8_node_steps(true);
}

namespace {

/// The four-lane triangle test (and with `eight_lanes` the AVX pair test) against the
/// scalar watertight test, bit for bit.
void check_lane_triangle_tests(bool eight_lanes) {
    // A fine grid: rays through shared edges and vertices give exactly-zero edge functions.
    const TriangleMesh m = make_tiny_grid(12, 1.0f, 1.0f);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> coord(-1, 13);
    int bad = 0, hits = 0, checked = 0;
    const std::vector<Ray> random = make_random_rays(mesh_bounds(m), 4000 / kSanitizerDivisor, 8);
    for (size_t i = 0; i < random.size(); ++i) {
        Ray ray = random[i];
        if (i % 2 == 0)  // integer origins straight down: through grid vertices and edges
            ray =
                Ray{Vec3(float(coord(rng)) * 0.5f, float(coord(rng)) * 0.5f, 3.0f), Vec3(0.0f, 0.0f, -1.0f)};
        const TriangleRay tr(ray);
        for (size_t first = 0; first + 4 <= m.triangle_count(); first += 4) {
            TriangleBlock4 b{};
            TriangleVerts tri[4];
            for (int l = 0; l < 4; ++l) {
                const uint32_t* v = &m.indices[3 * (first + size_t(l))];
                tri[l] = TriangleVerts::of(m.positions[v[0]], m.positions[v[1]], m.positions[v[2]]);
                for (int k = 0; k < 3; ++k)
                    for (int a = 0; a < 3; ++a) b.p[k][a][l] = tri[l].p[k][a];
                b.slot[l] = uint32_t(l);
            }
            float t[4], u[4], v[4];
            const int mask = intersect_triangle_block4(tr, b, ray.tmin, ray.tmax, t, u, v);
            // The AVX pair test on (b, b) must give the same answer in both halves.
            alignas(32) float t8[8], u8[8], v8[8];
            const TriangleBlock4 pair[2] = {b, b};
            const int mask8 =
                eight_lanes ? intersect_triangle_blocks2_avx(tr, pair, ray.tmin, ray.tmax, t8, u8, v8) : 0;
            for (int l = 0; l < 4; ++l) {
                const std::optional<ShapeHit> found = tri[l].intersect(tr, ray.tmin, ray.tmax);
                const bool hit = found.has_value();
                const ShapeHit h = found.value_or(ShapeHit{});
                ++checked;
                hits += hit;
                if (hit != bool(mask & (1 << l)) || (hit && (h.t != t[l] || h.u != u[l] || h.v != v[l])))
                    ++bad;
                if (!eight_lanes) continue;
                for (int half = 0; half < 2; ++half) {
                    const int k = 4 * half + l;
                    if (hit != bool(mask8 & (1 << k)) ||
                        (hit && (h.t != t8[k] || h.u != u8[k] || h.v != v8[k])))
                        ++bad;
                }
            }
        }
    }
    CHECK(bad == 0);
    CHECK(hits > 0);
    CHECK(checked > 0);
}

}  // namespace

TEST_CASE("four-lane triangle test is bit-identical to the scalar watertight test") {
    check_lane_triangle_tests(false);
}

TEST_CASE("eight-lane (AVX pair) triangle test is bit-identical to the scalar watertight test [needs AVX2]" *
          doctest::skip(!cpu_has_avx2())) {
    check_lane_triangle_tests(true);
}
