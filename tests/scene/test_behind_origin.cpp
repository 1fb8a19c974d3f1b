// Rays that start just off a triangle's plane: a ray whose origin lies behind the plane
// (the true t is negative) must not hit the triangle at tmin = 0, however close the
// origin; a ray whose origin lies in front must still hit. The true side comes from the
// plane in double over the same float inputs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "accel/packet.h"
#include "accel/simd_path.h"
#include "geometry/triangle.h"
#include "scene/accelerator.h"
#include "math/vec3.h"
#include "scene/mesh_scene.h"

using namespace sahara;

namespace {

/// Where the ray meets the triangle's plane, in double (the float inputs are exact there).
double plane_t(const TriangleVerts& tri, const Ray& r) {
    const Vec3d p0 = Vec3d(tri.vertex(0));
    const Vec3d n = cross(Vec3d(tri.vertex(1)) - p0, Vec3d(tri.vertex(2)) - p0);
    return dot(n, p0 - Vec3d(r.origin)) / dot(n, Vec3d(r.dir));
}

/// The distance within which the watertight test may reject a hit as possibly behind the
/// origin: t_scaled_error_bound over |det|, with the sheared vertices in double.
double rejection_distance(const TriangleVerts& tri, const Ray& r) {
    const TriangleRay tr(r);
    double max_x = 0.0, max_y = 0.0, max_z = 0.0, sx[3], sy[3];
    for (int v = 0; v < 3; ++v) {
        const double z = double(tri.p[v][tr.kz]) - double(tr.org[tr.kz]);
        sx[v] = double(tri.p[v][tr.kx]) - double(tr.org[tr.kx]) - double(tr.sx) * z;
        sy[v] = double(tri.p[v][tr.ky]) - double(tr.org[tr.ky]) - double(tr.sy) * z;
        max_x = std::max(max_x, std::fabs(sx[v]));
        max_y = std::max(max_y, std::fabs(sy[v]));
        max_z = std::max(max_z, std::fabs(z));
    }
    const double det =
        (sx[2] * sy[1] - sy[2] * sx[1]) + (sx[0] * sy[2] - sy[0] * sx[2]) + (sx[1] * sy[0] - sy[1] * sx[0]);
    float bound = 0.0f;
    t_scaled_error_bound(float(max_x), float(max_y), float(max_z), float(std::fabs(det)), std::fabs(tr.sz),
                         bound);
    return double(bound) / std::fabs(det);
}

/// A triangle with the rays aimed at it, in packets of 16 rays of one octant.
struct Target {
    TriangleVerts tri;
    std::vector<Ray> rays;
    std::vector<double> t;      ///< each ray's true (plane) t
    std::vector<double> limit;  ///< each ray's rejection_distance
};

/// Whether a direction keeps to one watertight-test permutation and octant under small
/// jitter (so a packet of its jittered copies takes the packet kernel).
bool clear_of_octant_edges(Vec3d d) {
    const double a[3] = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
    const double lo = std::min({a[0], a[1], a[2]}), hi = std::max({a[0], a[1], a[2]});
    const double mid = a[0] + a[1] + a[2] - lo - hi;
    return lo > 0.1 && hi - mid > 0.1;
}

/// Triangles near the world origin and far from it, well shaped and slivers (aspect 100),
/// in random orientations; through each, rays whose origins sit a distance of 1e-7 to
/// 1e-3 times the coordinates' magnitude behind or in front of the plane, as packets of
/// 16 with directions within about 70 degrees of the normal.
std::vector<Target> make_targets() {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    struct Placement {
        Vec3d center;
        double size;
    };
    const Placement placements[] = {
        {{0.3, -0.2, 0.1}, 1.0}, {{1.5, 2.5, -3.0}, 0.2}, {{700.5, -300.25, 400.0}, 30.0}};
    std::vector<Target> out;
    for (const Placement& pl : placements)
        for (const bool sliver : {false, true})
            for (int k = 0; k < 8; ++k) {
                const Vec3d a = normalize(Vec3d(u(rng), u(rng), u(rng)));
                const Vec3d b = normalize(cross(a, Vec3d(u(rng), u(rng), u(rng))));
                const double s = pl.size;
                Target tg;
                const Vec3d v0 = pl.center + a * s,
                            v1 = pl.center + a * (sliver ? -s : -0.5 * s) + b * (sliver ? 0.0 : 0.87 * s),
                            v2 = pl.center + a * (sliver ? 0.0 : -0.5 * s) +
                                 b * (sliver ? 0.02 * s : -0.87 * s);
                tg.tri = TriangleVerts::of(Vec3(v0), Vec3(v1), Vec3(v2));
                const Vec3d p0 = Vec3d(tg.tri.vertex(0)), e1 = Vec3d(tg.tri.vertex(1)) - p0,
                            e2 = Vec3d(tg.tri.vertex(2)) - p0;
                const Vec3d n = normalize(cross(e1, e2));
                const double magnitude =
                    std::max({std::fabs(pl.center.x), std::fabs(pl.center.y), std::fabs(pl.center.z)}) + s;
                for (const double rel : {1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 1e-4, 1e-3})
                    for (const double side : {-1.0, 1.0})
                        for (int packet = 0; packet < 2; ++packet) {
                            Vec3d base;
                            do {
                                base = normalize(n * (u(rng) < 0.0 ? -1.0 : 1.0) +
                                                 Vec3d(u(rng), u(rng), u(rng)) * 1.6);
                            } while (!clear_of_octant_edges(base) || std::fabs(dot(base, n)) < 0.3);
                            for (int i = 0; i < kPacketSize; ++i) {
                                const Vec3d d = normalize(base + Vec3d(u(rng), u(rng), u(rng)) * 0.01);
                                // An interior point away from the edges.
                                double b1 = 0.15 + 0.35 * (u(rng) + 1.0) * 0.5,
                                       b2 = 0.15 + 0.35 * (u(rng) + 1.0) * 0.5;
                                const Vec3d hit = p0 + e1 * b1 + e2 * b2;
                                const double along = rel * magnitude / std::fabs(dot(d, n));
                                // side -1: the plane lies behind the origin (t < 0).
                                const Ray r{Vec3(hit + d * (-side * along)), Vec3(d)};
                                tg.rays.push_back(r);
                                tg.t.push_back(plane_t(tg.tri, r));
                                tg.limit.push_back(rejection_distance(tg.tri, r));
                            }
                        }
                out.push_back(tg);
            }
    return out;
}

/// Rays that report a hit on a triangle behind their origin, and rays in front of it
/// beyond twice the rejection distance that miss it, per way of tracing. Rays in front
/// nearer than that may go either way (`near_missed` counts those that miss).
struct Tally {
    int behind = 0, front = 0, near = 0, wrong_hits = 0, lost_hits = 0, near_missed = 0;
};

std::string describe(const Tally& t) {
    return std::to_string(t.wrong_hits) + " of " + std::to_string(t.behind) + " rays behind hit, " +
           std::to_string(t.lost_hits) + " of " + std::to_string(t.front) + " in front missed, " +
           std::to_string(t.near_missed) + " of " + std::to_string(t.near) + " nearer missed";
}

void count(Tally& tally, const Target& tg, size_t i, bool hit) {
    if (tg.t[i] < 0.0) {
        ++tally.behind;
        tally.wrong_hits += hit;
    } else if (tg.t[i] > 2.02 * tg.limit[i]) {
        // Beyond twice the distance: the computed t errs by at most the distance, so it
        // still clears it (margin: the distance's maxima are rounded to float here).
        ++tally.front;
        tally.lost_hits += !hit;
    } else {
        ++tally.near;
        tally.near_missed += !hit;
    }
}

/// Restores automatic SIMD path selection when a test ends.
struct SimdPathGuard {
    ~SimdPathGuard() { clear_forced_simd_path(); }
};

AcceleratorOptions with_layout(BvhLayout layout) {
    AcceleratorOptions o;
    o.layout = layout;
    return o;
}

}  // namespace

TEST_CASE("no hit on a triangle just behind the ray origin and none lost just in front: scalar test") {
    Tally tally;
    for (const Target& tg : make_targets())
        for (size_t i = 0; i < tg.rays.size(); ++i) {
            const Ray& r = tg.rays[i];
            count(tally, tg, i, tg.tri.intersect(TriangleRay(r), 0.0f, kInfinity).has_value());
        }
    INFO(describe(tally));
    CHECK(tally.behind > 1000);
    CHECK(tally.front > 1000);
    CHECK(tally.wrong_hits == 0);
    CHECK(tally.lost_hits == 0);
    CHECK(tally.near_missed * 100 < tally.near);  // hits within the bound are decided, not dropped
}

TEST_CASE(
    "no hit on a triangle just behind the ray origin and none lost just in front: every SIMD path and "
    "layout") {
    SimdPathGuard guard;
    const std::vector<Target> targets = make_targets();
    for (const BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs})
        for (const SimdPath path : runnable_simd_paths()) {
            force_simd_path(path);
            Tally closest, any, packets;
            for (const Target& tg : targets) {
                TriangleMesh mesh;
                for (int v = 0; v < 3; ++v) mesh.positions.push_back(tg.tri.vertex(v));
                mesh.indices = {0, 1, 2};
                const Accelerator acc(scene_from_mesh(mesh), with_layout(layout));
                for (size_t first = 0; first < tg.rays.size(); first += kPacketSize) {
                    RayPacket packet;
                    for (int i = 0; i < kPacketSize; ++i) {
                        Ray r = tg.rays[first + size_t(i)];
                        packet.set(i, r);
                        Hit h;
                        count(closest, tg, first + size_t(i), acc.intersect(r, h));
                        count(any, tg, first + size_t(i), acc.occluded(tg.rays[first + size_t(i)]));
                    }
                    packet.active = 0xFFFFu;
                    HitPacket hits;
                    acc.intersect_packet(packet, hits);
                    for (int i = 0; i < kPacketSize; ++i)
                        count(packets, tg, first + size_t(i), hits.hit(i).hit());
                }
            }
            INFO(std::string(simd_path_name(path)), " ", std::string(bvh_layout_name(layout)));
            INFO("closest hit: ", describe(closest));
            INFO("any hit: ", describe(any));
            INFO("packets: ", describe(packets));
            CHECK(closest.behind > 1000);
            CHECK(closest.wrong_hits == 0);
            CHECK(any.wrong_hits == 0);
            CHECK(packets.wrong_hits == 0);
            CHECK(closest.lost_hits == 0);
            CHECK(any.lost_hits == 0);
            CHECK(packets.lost_hits == 0);
            CHECK(closest.near_missed * 100 < closest.near);
            CHECK(any.near_missed * 100 < any.near);
            CHECK(packets.near_missed * 100 < packets.near);
        }
}
