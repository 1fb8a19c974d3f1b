#include <doctest/doctest.h>

#include <cmath>

#include "math/sampling.h"
#include "render/camera.h"
#include "render/features.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render_test_util.h"
#include "io/scene_parser.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Inside a closed sphere that glows with Le and reflects with albedo rho.
Scene glowing_sphere(float rho, Rgb le) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(lambertian(Rgb(rho), le));
    d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
    return build_scene(d);
}

Ray ray_from_inside(const Vec3& origin, const Vec3& dir) {
    return Ray{origin, normalize(dir), 0.0f, kInfinity, 0.0f};
}

}  // namespace

TEST_CASE("inside a closed glowing sphere the radiance is Le / (1 - rho) (depth and roulette unbiased)") {
    const Rgb le(1.0f, 0.5f, 0.25f);
    for (float rho : {0.5f, 0.8f}) {
        CAPTURE(rho);
        const Scene scene = glowing_sphere(rho, le);
        for (const Ray& ray :
             {ray_from_inside({0, 0, 0}, {0, 1, 0}), ray_from_inside({0.3f, -0.5f, 0.2f}, {1, 1, -2})}) {
            const Stat s = radiance_stats(scene, ray, scaled(rho > 0.6f ? 40000 : 20000), 500);
            CHECK(within(s, le / (1.0f - rho), 4));
        }
    }
}

TEST_CASE("max_depth D counts rays per path, camera ray included") {
    const float rho = 0.6f;
    const Scene scene = glowing_sphere(rho, Rgb(1.0f));
    const Ray ray = ray_from_inside({0.1f, 0.2f, 0.0f}, {0.3f, 1, 0.2f});
    for (int depth : {1, 2, 3, 6, 9}) {
        CAPTURE(depth);
        // D rays see the emission D times: Le * (1 + rho + ... + rho^(D-1)).
        const float expected = (1.0f - std::pow(rho, float(depth))) / (1.0f - rho);
        const Stat s = radiance_stats(scene, ray, scaled(20000), depth);
        CHECK(within(s, Rgb(expected), 4));
    }
    CHECK(radiance_stats(scene, ray, 8, 1).mean.x == doctest::Approx(1.0f));  // emission only, no variance
}

TEST_CASE("with a point light, D = 2 is direct light only and D = 3 adds one bounce") {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(lambertian(Rgb(0.5f)));
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    d.planes.push_back({{0, 2, 0}, {0, -1, 0}, 1});  // a wall that bounces light onto the floor
    LightDesc l;
    l.position = {0, 1, 1};
    l.intensity = {3, 3, 3};
    d.lights = {l};
    const Scene scene = build_scene(d);
    const Ray ray{
        {0, -2, 1}, normalize(Vec3(0, 2, -1)), 0.0f, kInfinity, 0.0f};  // hits the floor at the origin
    const float direct = 0.5f * kInvPi * 3.0f * (1.0f / std::sqrt(2.0f)) / 2.0f;
    CHECK(radiance_stats(scene, ray, 16, 1).mean.x == 0.0f);
    const Stat two = radiance_stats(scene, ray, 16, 2);
    CHECK(two.mean.x == doctest::Approx(direct).epsilon(1e-5));
    const Stat three = radiance_stats(scene, ray, scaled(4000), 3);
    CHECK(three.mean.x > direct + 5 * three.se.x);
}

TEST_CASE("whitted: direct light, ambient, mirror and glass") {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.render.integrator = IntegratorType::whitted;
    d.materials.push_back(lambertian(Rgb(0.5f)));
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    LightDesc l;
    l.position = {1, 0, 2};
    l.intensity = {4, 4, 4};
    d.lights = {l};
    Sampler sampler(0);
    const Ray down{{0, -1, 1}, normalize(Vec3(0, 1, -1)), 0.0f, kInfinity, 0.0f};
    {
        const Scene scene = build_scene(d);
        const float d2 = 5.0f, cos = 2.0f / std::sqrt(5.0f);
        CHECK(estimate_radiance(scene, down, sampler, 2).x ==
              doctest::Approx(0.5f * kInvPi * 4.0f * cos / d2));
        CHECK(estimate_radiance(scene, down, sampler, 1).x == 0.0f);
    }
    // Ambient: albedo times the sky in the normal direction.
    d.lights.clear();
    d.background.color = Rgb(1.0f);
    CHECK(estimate_radiance(build_scene(d), down, sampler, 4).x == doctest::Approx(0.5f));
    // Glass and mirror spheres in the furnace (glass branches are Fresnel-weighted).
    for (const MaterialDesc& m : {dielectric(1.5f), metal(Rgb(1.0f), 0.3f)}) {
        SceneDesc g = empty_scene(Rgb(1.0f));
        g.render.integrator = IntegratorType::whitted;
        g.materials.push_back(m);
        g.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
        const Scene scene = build_scene(g);
        for (float x : {0.0f, 0.5f, 0.9f})
            CHECK(estimate_radiance(scene, Ray{{x, -5, 0.1f}, {0, 1, 0}, 0.0f, kInfinity, 0.0f}, sampler, 16)
                      .x == doctest::Approx(1.0f).epsilon(1e-3));
    }
}

TEST_CASE("inspection integrators: normals and depth") {
    SceneDesc d = empty_scene(Rgb(0.3f));
    d.planes.push_back({{0, 0, -2}, {0, 0, 1}, 0});
    d.render.integrator = IntegratorType::normals;
    Sampler sampler(0);
    const Ray ray{{0, 0, 0}, {0, 0, -1}, 0.0f, kInfinity, 0.0f};
    CHECK(estimate_radiance(build_scene(d), ray, sampler, 4) == Rgb(0.5f, 0.5f, 1.0f));
    d.render.integrator = IntegratorType::depth;
    CHECK(estimate_radiance(build_scene(d), ray, sampler, 4).x == doctest::Approx(2.0f));
    d.render.integrator = IntegratorType::albedo;
    CHECK(estimate_radiance(build_scene(d), Ray{{0, 0, 0}, {0, 0, 1}, 0.0f, kInfinity, 0.0f}, sampler, 4) ==
          Rgb(0.3f));
}

TEST_CASE("depth of field: a point at the focus distance stays sharp") {
    CameraDesc c;
    c.position = {0, 0, 0};
    c.look_at = {0, 10, 0};
    c.up = {0, 0, 1};
    c.aperture = 0.5f;
    c.focus_distance = 5.0f;
    const Camera camera(c, 64, 48);
    Sampler s(3);
    for (Vec2 px : {Vec2{32, 24}, Vec2{5.5f, 40.25f}}) {
        Bounds3 at_focus, behind;
        for (uint32_t i = 0; i < 64; ++i) {
            s.start(1, 1, i);
            const Ray r = camera.generate_ray(px.x, px.y, s.next_2d(), 0.5f);
            // The planes y = 5 (the focal plane straight ahead) and y = 10.
            at_focus.extend(r.at((5.0f - r.origin.y) / r.dir.y));
            behind.extend(r.at((10.0f - r.origin.y) / r.dir.y));
        }
        CHECK(max_component(at_focus.extent()) < 1e-4f);
        CHECK(max_component(behind.extent()) > 0.2f);
    }
}

namespace {

/// An emissive sphere on black seen by a 32x24 camera; the mean of the image.
double image_mean(const SceneDesc& d, double* se) {
    const Scene scene = build_scene(d);
    Film film(d.render.width, d.render.height);
    RenderOptions o;
    o.threads = 1;
    render_image(scene, film, o);
    double sum = 0, var = 0;
    const double n = double(d.render.width) * d.render.height;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            sum += double(film.mean(x, y).x);
            var += film.luminance_variance(x, y) / film.count(x, y);
        }
    *se = std::sqrt(var) / n;
    return sum / n;
}

SceneDesc moving_sphere_scene(Vec3 center, Vec3 velocity) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(emissive(Rgb(1.0f)));
    d.spheres.push_back({center, 0.8f, 1, velocity});
    d.camera.position = {0, -6, 0};
    d.camera.look_at = {0, 0, 0};
    d.camera.vfov = 40;
    d.render.width = 32;
    d.render.height = 24;
    d.render.spp = scaled(256);
    d.render.max_depth = 1;
    return d;
}

}  // namespace

TEST_CASE("motion blur: the blurred image's mean equals the average of static renders") {
    // Moving away from the camera too, so that the image mean changes over the shutter.
    const Vec3 center(-0.6f, 0, 0.1f), velocity(1.2f, 3.0f, 0.5f);
    double se_blur = 0;
    const double blurred = image_mean(moving_sphere_scene(center, velocity), &se_blur);
    constexpr int kSteps = 8;
    double sum = 0, var = 0;
    for (int k = 0; k < kSteps; ++k) {
        double se = 0;
        const float t = (float(k) + 0.5f) / kSteps;
        sum += image_mean(moving_sphere_scene(center + velocity * t, Vec3(0.0f)), &se);
        var += se * se;
    }
    const double statics = sum / kSteps, se_static = std::sqrt(var) / kSteps;
    CHECK(std::abs(blurred - statics) <
          4 * std::sqrt(se_blur * se_blur + se_static * se_static) + 2e-3 * statics);
    // The sphere frozen at the shutter's opening covers a different mean: the test can fail.
    double se0 = 0;
    CHECK(image_mean(moving_sphere_scene(center, Vec3(0.0f)), &se0) !=
          doctest::Approx(blurred).epsilon(0.02));
}

TEST_CASE("scene features pick the kernel, and forcing turns everything on") {
    const Scene plain = build_scene(default_scene());
    CHECK(!plain.features.has_lights);
    CHECK(!plain.features.has_emitters);
    CHECK(plain.features.lambertian_only);
    CHECK(!plain.features.has_motion);
    CHECK(std::string(path_kernel_name(plain)) == "path<no light sampling, lambertian only>");
    CHECK(describe_features(plain).find("lambertian only") != std::string::npos);

    Scene forced = build_scene(default_scene());
    forced.prepare_lighting(true);
    CHECK(forced.features.forced_all);
    CHECK(std::string(path_kernel_name(forced)) == "path<MIS, all materials>");
    // Same scene, general kernel: the same image up to noise.
    const Ray ray{{0, 0, 0}, normalize(Vec3(0.2f, 1, -0.3f)), 0.0f, kInfinity, 0.0f};
    CHECK(agree(radiance_stats(plain, ray, scaled(4000), 8), radiance_stats(forced, ray, scaled(4000), 8, 2),
                4));

    SceneDesc d = default_scene();
    d.materials.push_back(dielectric(1.5f));
    d.spheres[0].velocity = {1, 0, 0};
    LightDesc l;
    l.intensity = {1, 1, 1};
    d.lights.push_back(l);
    const Scene rich = build_scene(d);
    CHECK(rich.features.has_delta_lights_only);
    CHECK(rich.features.has_dielectric);
    CHECK(rich.features.has_motion);
    CHECK(std::string(path_kernel_name(rich)) == "path<delta lights, all materials>");
}
