#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "math/sampling.h"
#include "render/background.h"
#include "render/lights.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A Lambertian floor z = 0 (material 1) under a black sky.
SceneDesc floor_scene(Rgb albedo) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(lambertian(albedo));
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    return d;
}

/// A ray from above straight down onto floor point p.
Ray ray_to(const Vec3& p, const Vec3& from) { return Ray{from, normalize(p - from), 0.0f, kInfinity, 0.0f}; }

Rgb point_light_radiance(const LightDesc& l, const Vec3& p, const Rgb& albedo) {
    const Vec3 d = l.position - p;
    const float d2 = length_squared(d), cos = d.z / std::sqrt(d2);
    return albedo * kInvPi * l.intensity * (std::max(0.0f, cos) / d2);
}

}  // namespace

TEST_CASE("point lights over a Lambertian plane give albedo/pi * I cos / d^2") {
    const Rgb albedo(0.6f, 0.5f, 0.4f);
    SceneDesc d = floor_scene(albedo);
    LightDesc a, b;
    a.position = {0.3f, -0.2f, 2.0f};
    a.intensity = {5, 4, 3};
    b.position = {-1.0f, 1.0f, 1.5f};
    b.intensity = {2, 2, 2};
    d.lights = {a, b};
    const Scene scene = build_scene(d);
    CHECK(scene.features.has_delta_lights_only);
    const Vec3 points[] = {{0, 0, 0}, {0.3f, -0.2f, 0}, {1.5f, 0.5f, 0}, {-2, 3, 0}, {4, -1, 0}};
    for (const Vec3& p : points) {
        CAPTURE(p.x);
        CAPTURE(p.y);
        const Rgb expected = point_light_radiance(a, p, albedo) + point_light_radiance(b, p, albedo);
        const Ray ray = ray_to(p, p + Vec3(0.5f, 0.2f, 3.0f));
        // Two lights picked by power: a random choice, so the estimate has variance.
        const Stat s = radiance_stats(scene, ray, scaled(4000), 5);
        CHECK(within(s, expected, 3));
        CHECK(s.se.x > 0);
        // max_depth 1: the camera ray alone, no shadow ray.
        CHECK(radiance_stats(scene, ray, 16, 1).mean == Rgb(0.0f));
    }
}

TEST_CASE("a sphere between a point light and the plane casts a hard shadow") {
    const Rgb albedo(0.5f);
    SceneDesc d = floor_scene(albedo);
    LightDesc a, b;
    a.position = {0, 0, 4};
    a.intensity = {10, 10, 10};
    b.position = {3, 0, 3};
    b.intensity = {1, 1, 1};
    d.lights = {a, b};
    d.spheres.push_back({{0, 0, 2}, 0.5f, 1, {0, 0, 0}});  // blocks light a at the origin only
    const Scene scene = build_scene(d);
    const Vec3 p(0, 0, 0);
    const Stat s = radiance_stats(scene, ray_to(p, {0.2f, -2.5f, 1.0f}), scaled(4000), 2);
    CHECK(within(s, point_light_radiance(b, p, albedo), 3));
}

TEST_CASE("a directional light gives albedo/pi * E cos") {
    const Rgb albedo(0.7f, 0.3f, 0.2f);
    SceneDesc d = floor_scene(albedo);
    LightDesc l;
    l.type = LightDesc::Type::directional;
    l.direction = {1, 0, -1};
    l.irradiance = {2, 3, 4};
    d.lights = {l};
    // A second plane facing the light head-on; the floor for x < 50 lies on its lit side.
    d.materials.push_back(lambertian(albedo));
    d.planes.push_back({{50, 0, 0}, normalize(Vec3(-1, 0, 1)), 2});
    const Scene scene = build_scene(d);
    const Rgb floor_expected = albedo * kInvPi * l.irradiance * (1.0f / std::sqrt(2.0f));
    for (const Vec3& p : {Vec3(0, 0, 0), Vec3(2, -3, 0), Vec3(-5, 1, 0)}) {
        const Stat s =
            radiance_stats(scene, ray_to(p, p + Vec3(0, 1, 2)), 64, 2);  // D = 2: no light between the planes
        CHECK(within(s, floor_expected, 3));
    }
    // On the tilted plane the light arrives at normal incidence.
    const Stat s = radiance_stats(scene, ray_to({52, 0, 2}, {50, -1, 4}), 64, 2);
    CHECK(within(s, albedo * kInvPi * l.irradiance, 3));
}

namespace {

/// A floor, a rough metal ball, and two sphere lights of very different sizes.
SceneDesc area_light_scene() {
    SceneDesc d = floor_scene(Rgb(0.7f));
    d.materials.push_back(emissive({40, 30, 20}));           // 2: small and bright
    d.materials.push_back(emissive({0.5f, 0.6f, 0.8f}));     // 3: large and dim
    d.materials.push_back(metal({0.9f, 0.8f, 0.6f}, 0.4f));  // 4
    d.spheres.push_back({{1, 0, 1.5f}, 0.15f, 2, {0, 0, 0}});
    d.spheres.push_back({{-3, 2, 3}, 2.0f, 3, {0, 0, 0}});
    d.spheres.push_back({{0, 1, 0.6f}, 0.6f, 4, {0, 0, 0}});
    return d;
}

}  // namespace

TEST_CASE("MIS, BSDF sampling only and light sampling only agree with area lights") {
    const Scene scene = build_scene(area_light_scene());
    REQUIRE(scene.emitters.size() == 2);
    CHECK(std::string(path_kernel_name(scene)) == "path<MIS, all materials>");
    const Vec3 eye(0, -4, 2);
    const Vec3 targets[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.6f}, {0.3f, 0.6f, 1.1f}, {-1.5f, 1, 0}};
    int mis_better = 0;
    for (const Vec3& t : targets) {
        CAPTURE(t.x);
        CAPTURE(t.y);
        const Ray ray = ray_to(t, eye);
        auto stats = [&](LightStrategy st, int n) {  // independent streams per strategy
            return sample_stats(n, 3 + uint64_t(st),
                                [&](Sampler& s) { return path_trace_with(scene, ray, s, 6, st); });
        };
        const Stat mis = stats(LightStrategy::mis, scaled(8000));
        const Stat bsdf = stats(LightStrategy::bsdf_only, scaled(80000));
        const Stat light = stats(LightStrategy::light_only, scaled(8000));
        CHECK(agree(mis, bsdf, 4));
        CHECK(agree(mis, light, 4));
        CHECK(mis.mean.x > 0);
        // Standard deviation per sample (bsdf had 10x the samples): MIS at least twice as good.
        const float ratio = luminance(bsdf.se) * std::sqrt(10.0f) / luminance(mis.se);
        mis_better += ratio > 2.0f;
    }
    // The small bright light makes BSDF sampling alone very noisy on diffuse surfaces.
    CHECK(mis_better >= 4);
}

TEST_CASE("a sphere light is sampled by solid angle: the cone pdf matches the hit pdf") {
    const Scene scene = build_scene(area_light_scene());
    const Vec3 p(0.2f, -0.3f, 0.0f);
    Sampler sampler(5);
    int ok = 0;
    for (int i = 0; i < 500; ++i) {
        sampler.start(1, 2, uint32_t(i));
        LightSample ls;
        const float u_sel = sampler.next_1d();
        if (!sample_light(scene, p, 0.0f, u_sel, sampler.next_2d(), ls)) continue;
        // Find the sampled point by tracing towards it; its density must agree.
        Ray r{p, ls.wi, 0.0f, kInfinity, 0.0f};
        Hit hit;
        REQUIRE(scene.intersect(r, hit));
        const SurfaceInteraction si = scene.interact(r, hit);
        const uint32_t e = emitter_of_hit(scene, hit);
        if (e == kNoEmitter) continue;  // the metal ball is in the way
        CHECK(si.front_face);
        CHECK(hit.t == doctest::Approx(ls.distance).epsilon(1e-3));
        CHECK(area_light_pdf(scene, e, p, si.p, si.ng, 0.0f) == doctest::Approx(ls.pdf).epsilon(1e-3));
        ++ok;
    }
    CHECK(ok > 300);
}

namespace {

/// The floor under one emissive triangle (radiance 4) at height 1, facing down.
Scene floor_under_triangle_light() {
    SceneDesc d = floor_scene(Rgb(0.5f));
    d.materials.push_back(emissive({4, 4, 4}));
    TriangleMesh m;
    // Facing down (counter-clockwise seen from below) at height 1.
    m.positions = {{-0.5f, -0.5f, 1}, {0.5f, 0.5f, 1}, {0.5f, -0.5f, 1}};
    m.indices = {0, 1, 2};
    m.material = 2;
    d.meshes.push_back(m);
    return build_scene(d);
}

}  // namespace

TEST_CASE("an emissive triangle is an area light (needs triangles in the accelerator)") {
    const Scene scene = floor_under_triangle_light();
    REQUIRE(scene.emitters.size() == 1);
    Ray probe{{0.2f, -0.2f, 0.5f}, {0, 0, 1}, 0.0f, kInfinity, 0.0f};
    Hit hit;
    REQUIRE(scene.intersect(probe, hit));
    REQUIRE(prim_kind(hit.prim) == PrimKind::triangle);
    const Ray ray = ray_to({0.1f, 0.1f, 0}, {0, -3, 2});
    auto stats = [&](LightStrategy st, int n) {
        return sample_stats(n, 9 + uint64_t(st),
                            [&](Sampler& s) { return path_trace_with(scene, ray, s, 3, st); });
    };
    const Stat mis = stats(LightStrategy::mis, scaled(8000));
    CHECK(agree(mis, stats(LightStrategy::bsdf_only, scaled(16000)), 4));
    CHECK(agree(mis, stats(LightStrategy::light_only, scaled(8000)), 4));
    CHECK(mis.mean.x > 0.1f);
}

namespace {

/// A small HDR lat-long image: dim, varying sky with one very bright pixel.
std::shared_ptr<Image> test_envmap() {
    auto img = std::make_shared<Image>();
    img->width = 16;
    img->height = 8;
    img->rgba.resize(16 * 8 * 4);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) {
            float* p = &img->rgba[size_t(y * 16 + x) * 4];
            p[0] = 0.1f + 0.05f * float(x % 3);
            p[1] = 0.2f + 0.02f * float(y);
            p[2] = (y >= 6) ? 0.0f : 0.3f;  // the two bottom rows are black: never sampled
            p[3] = 1;
        }
    float* sun = &img->rgba[size_t(2 * 16 + 5) * 4];
    sun[0] = 500;
    sun[1] = 400;
    sun[2] = 300;
    return img;
}

SceneDesc envmap_scene() {
    SceneDesc d = floor_scene(Rgb(0.8f));
    d.background.type = BackgroundDesc::Type::envmap;
    d.background.image = test_envmap();
    d.background.up = {0, 0, 1};
    d.background.strength = 0.5f;
    return d;
}

}  // namespace

TEST_CASE("envmap importance sampling: pdfs agree and L/pdf integrates the map") {
    const Scene scene = build_scene(envmap_scene());
    REQUIRE(scene.envmap_emitter != kNoEmitter);
    REQUIRE(scene.emitters.size() == 1);
    // Exact integral of the piecewise-constant map over the sphere, per channel.
    const Image& img = *scene.background.image;
    Vec3d exact(0.0);
    for (int y = 0; y < img.height; ++y) {
        const double dz = std::cos(M_PI * y / img.height) - std::cos(M_PI * (y + 1) / img.height);
        for (int x = 0; x < img.width; ++x) {
            const float* p = &img.rgba[size_t(y * img.width + x) * 4];
            exact += Vec3d(p[0], p[1], p[2]) * (dz * 2 * M_PI / img.width * 0.5);
        }
    }
    const Vec3 p(0, 0, 0);
    int mismatches = 0;  // a direction rounded across a pixel edge may land in the neighbour
    const Stat s = sample_stats(scaled(20000), 11, [&](Sampler& sampler) {
        LightSample ls;
        const float u_sel = sampler.next_1d();
        if (!sample_light(scene, p, 0.0f, u_sel, sampler.next_2d(), ls)) return Rgb(0.0f);
        mismatches += envmap_light_pdf(scene, ls.wi) != doctest::Approx(ls.pdf).epsilon(2e-3) ||
                      eval_background(scene.background, ls.wi) != ls.li;
        return ls.li / ls.pdf;
    });
    CHECK(mismatches <= scaled(20000) / 2000);
    CHECK(within(s, Rgb(exact), 4, 1e-3f));
}

TEST_CASE("envmap lighting: MIS agrees with BSDF sampling") {
    const Scene scene = build_scene(envmap_scene());
    for (const Vec3& t : {Vec3(0, 0, 0), Vec3(2, 1, 0)}) {
        const Ray ray = ray_to(t, {0, -3, 2});
        auto stats = [&](LightStrategy st, int n) {
            return sample_stats(n, 13 + uint64_t(st),
                                [&](Sampler& s) { return path_trace_with(scene, ray, s, 4, st); });
        };
        const Stat mis = stats(LightStrategy::mis, scaled(8000));
        const Stat bsdf = stats(LightStrategy::bsdf_only, scaled(30000));
        CHECK(agree(mis, bsdf, 4));
        CHECK(agree(mis, stats(LightStrategy::light_only, scaled(8000)), 4));
        CHECK(mis.se.x < bsdf.se.x);
    }
}

TEST_CASE("the power heuristic stays in 0..1 and complementary when a density overflows its square") {
    const float inf = std::numeric_limits<float>::infinity();
    CHECK(power_heuristic(1.0f, 1.0f) == 0.5f);
    CHECK(power_heuristic(0.0f, 0.0f) == 0.0f);
    CHECK(power_heuristic(2.0f, 0.0f) == 1.0f);
    for (const float big : {1e19f, 1e25f, 3e38f, inf}) {
        for (const float other : {0.0f, 1e-3f, 1.0f, 1e18f, 1e30f}) {
            const float w = power_heuristic(big, other), w_other = power_heuristic(other, big);
            CAPTURE(big);
            CAPTURE(other);
            REQUIRE(std::isfinite(w));
            REQUIRE(std::isfinite(w_other));
            CHECK((w >= 0.5f) == (big >= other));
            CHECK(w <= 1.0f);
            CHECK(w + w_other == doctest::Approx(1.0f).epsilon(1e-6));
        }
    }
    CHECK(power_heuristic(inf, inf) == 0.5f);
    CHECK(power_heuristic(1e30f, 1e20f) == doctest::Approx(1.0f));
    CHECK(power_heuristic(2e20f, 1e20f) == doctest::Approx(0.8f));
}

TEST_CASE("an area light seen from a plane far towards the horizon gives finite radiance") {
    // A camera ray grazing the infinite floor hits it some 1e9 away; from there the
    // emitting triangle is edge-on and its solid-angle density exceeds 1e19, whose
    // square overflowed the MIS weight to inf/inf = NaN before.
    const Scene scene = floor_under_triangle_light();
    for (const float slope : {1e-7f, 1e-8f, 1e-9f, 1e-10f}) {
        const Ray ray{{0, -3, 2}, normalize(Vec3{0, 1, -slope}), 0.0f, kInfinity, 0.0f};
        const Stat s = sample_stats(
            2000, 5, [&](Sampler& smp) { return path_trace_with(scene, ray, smp, 3, LightStrategy::mis); });
        CAPTURE(slope);
        CHECK(std::isfinite(s.mean.x));
        CHECK(std::isfinite(s.mean.y));
        CHECK(std::isfinite(s.mean.z));
    }
}
