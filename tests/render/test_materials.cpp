#include <doctest/doctest.h>

#include <cmath>

#include "math/sampling.h"
#include "render/bsdf.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

TEST_CASE("Fresnel reflectance of a dielectric") {
    for (float n : {1.33f, 1.5f, 2.4f}) {
        const float r0 = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
        CHECK(fresnel_dielectric(1.0f, n) == doctest::Approx(r0).epsilon(1e-6));
        CHECK(fresnel_dielectric(1.0f, 1.0f / n) == doctest::Approx(r0).epsilon(1e-6));
        CHECK(fresnel_dielectric(0.0f, n) == doctest::Approx(1.0f));
        // Reciprocity: the same pair of angles from either side reflects the same.
        for (float cos_i : {0.9f, 0.6f, 0.3f}) {
            const float sin_t = std::sqrt(1 - cos_i * cos_i) / n, cos_t = std::sqrt(1 - sin_t * sin_t);
            CHECK(fresnel_dielectric(cos_t, 1.0f / n) ==
                  doctest::Approx(fresnel_dielectric(cos_i, n)).epsilon(1e-5));
        }
        // Total internal reflection beyond the critical angle, from inside.
        const float cos_critical = std::sqrt(1 - 1 / (n * n));
        CHECK(fresnel_dielectric(cos_critical * 0.99f, 1.0f / n) == 1.0f);
        CHECK(fresnel_dielectric(cos_critical * 1.01f, 1.0f / n) < 1.0f);
    }
}

TEST_CASE("refraction obeys Snell's law") {
    const Vec3 n(0, 0, 1);
    const Vec3 wo = normalize(Vec3(0.6f, 0.1f, 0.8f));
    Vec3 wt;
    REQUIRE(refract(wo, n, 1.5f, &wt));
    CHECK(length(wt) == doctest::Approx(1.0f));
    const float sin_i = length(Vec3(wo.x, wo.y, 0)), sin_t = length(Vec3(wt.x, wt.y, 0));
    CHECK(sin_i == doctest::Approx(1.5f * sin_t));
    CHECK(wt.z < 0);
    CHECK(!refract(normalize(Vec3(0.9f, 0, 0.2f)), n, 1.0f / 1.5f, &wt));
}

namespace {

/// A sphere of material 1 at the origin under a constant sky.
Scene sphere_in_furnace(const MaterialDesc& m, Rgb sky) {
    SceneDesc d = empty_scene(sky);
    d.materials.push_back(m);
    d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
    return build_scene(d);
}

/// Rays from outside aimed at points across the sphere's disk.
std::vector<Ray> rays_at_sphere() {
    std::vector<Ray> rays;
    for (float x : {0.0f, 0.3f, 0.7f, 0.95f})
        for (float z : {0.0f, -0.25f}) rays.push_back(Ray{{x, -5, z}, {0, 1, 0}, 0.0f, kInfinity, 0.0f});
    return rays;
}

}  // namespace

TEST_CASE("furnace: glass and perfect mirror spheres under a sky of 1 render to 1") {
    for (const MaterialDesc& m : {dielectric(1.5f), metal(Rgb(1.0f), 0.0f)}) {
        const Scene scene = sphere_in_furnace(m, Rgb(1.0f));
        for (const Ray& ray : rays_at_sphere()) {
            const Stat s = radiance_stats(scene, ray, scaled(2000), 64);
            CHECK(within(s, Rgb(1.0f), 4, 1e-4f));
        }
    }
}

TEST_CASE("glass seen from inside: radiance n^2 times the sky (ray starts inside the sphere)") {
    // From the centre every ray meets the surface head-on; each path escapes
    // with weight n^2 = 2.25, the radiance of a dense medium in equilibrium.
    const Scene scene = sphere_in_furnace(dielectric(1.5f), Rgb(1.0f));
    for (const Vec3& dir : {Vec3(0, 1, 0), normalize(Vec3(1, -2, 0.5f))}) {
        const Stat s = radiance_stats(scene, Ray{{0, 0, 0}, dir, 0.0f, kInfinity, 0.0f}, scaled(2000), 64);
        CHECK(within(s, Rgb(2.25f), 4, 1e-4f));
    }
}

TEST_CASE("white furnace: a Lambertian sphere of albedo 0.5 renders to 0.5") {
    const Scene scene = sphere_in_furnace(lambertian(Rgb(0.5f)), Rgb(1.0f));
    for (const Ray& ray : rays_at_sphere()) {
        const Stat s = radiance_stats(scene, ray, scaled(2000), 16);
        CHECK(within(s, Rgb(0.5f), 4));
    }
}

TEST_CASE("GGX visible-normal sampling is consistent with evaluation") {
    for (float roughness : {0.2f, 0.5f, 0.9f}) {
        SurfaceInteraction si;
        si.ns = si.ng = {0, 0, 1};
        const Bsdf b = make_bsdf(metal({0.9f, 0.6f, 0.3f}, roughness), si, {});
        REQUIRE(b.kind == BsdfKind::ggx);
        for (float cos_o : {0.9f, 0.5f, 0.15f}) {
            CAPTURE(roughness);
            CAPTURE(cos_o);
            const Vec3 wo(std::sqrt(1 - cos_o * cos_o), 0, cos_o);
            // Each sample: weight = f cos / pdf, and eval gives the same pdf.
            const Stat sampled = sample_stats(scaled(20000), 17, [&](Sampler& s) {
                BsdfSample bs;
                if (!sample_bsdf(b, wo, s.next_2d(), s.next_1d(), bs)) return Rgb(0.0f);
                float pdf = 0;
                const Rgb f = eval_bsdf(b, wo, bs.wi, &pdf);
                CHECK(pdf == doctest::Approx(bs.pdf).epsilon(1e-3));
                CHECK(f.x / pdf == doctest::Approx(bs.weight.x).epsilon(1e-3));
                return bs.weight;
            });
            // The directional albedo again, by uniform hemisphere sampling.
            const Stat uniform = sample_stats(scaled(60000), 19, [&](Sampler& s) {
                Vec3 wi = sample_uniform_sphere(s.next_2d());
                wi.z = std::abs(wi.z);
                float pdf = 0;
                return eval_bsdf(b, wo, wi, &pdf) * (2 * kPi);
            });
            CHECK(agree(sampled, uniform, 4));
            CHECK(max_component(sampled.mean) <= 1.0f);
        }
    }
}

TEST_CASE("a rough metal sphere in the furnace reflects at most its albedo") {
    const Scene scene = sphere_in_furnace(metal(Rgb(1.0f), 0.5f), Rgb(1.0f));
    const Stat s = radiance_stats(scene, rays_at_sphere()[1], scaled(4000), 16);
    CHECK(s.mean.x <= 1.0f + 3 * s.se.x);
    CHECK(s.mean.x > 0.8f);  // single-scattering GGX loses a little energy at this roughness
}

TEST_CASE("checkerboard albedo is evaluated at the hit point") {
    SceneDesc d = empty_scene(Rgb(1.0f));
    MaterialDesc m = lambertian(Rgb(0.5f));
    m.albedo.kind = ColorSource::Kind::checker;
    m.albedo.even = Rgb(0.8f);
    m.albedo.odd = Rgb(0.2f);
    m.albedo.checker_scale = 1.0f;
    d.materials.push_back(m);
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});  // z = 0 is a cell boundary: hits must not straddle it
    d.render.integrator = IntegratorType::albedo;
    const Scene scene = build_scene(d);
    CHECK(scene.features.has_textures);
    Sampler s(0);
    CHECK(estimate_radiance(scene, Ray{{0.5f, 0.5f, 1}, {0, 0, -1}, 0, kInfinity, 0}, s, 4).x ==
          doctest::Approx(0.8f));
    CHECK(estimate_radiance(scene, Ray{{1.5f, 0.5f, 1}, {0, 0, -1}, 0, kInfinity, 0}, s, 4).x ==
          doctest::Approx(0.2f));
    for (int i = 0; i < 200; ++i) {  // from many directions, the same cell
        const Vec3 target(0.1f + 0.004f * float(i), 0.7f - 0.003f * float(i), 0.0f);
        const Vec3 eye(std::sin(float(i)) * 7.0f, std::cos(float(i)) * 7.0f, 0.5f + 0.037f * float(i));
        const Ray ray{eye, normalize(target - eye), 0, kInfinity, 0};
        CHECK(estimate_radiance(scene, ray, s, 4).x == doctest::Approx(0.8f));
    }
    // Under a white sky a checkered floor reflects its albedo.
    d.render.integrator = IntegratorType::path;
    const Scene lit = build_scene(d);
    const Stat st = radiance_stats(lit, Ray{{1.5f, 0.5f, 1}, {0, 0, -1}, 0, kInfinity, 0}, 256, 4);
    CHECK(within(st, Rgb(0.2f), 3));
}
