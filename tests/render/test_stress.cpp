// Numerical stability stress tests: self-intersection, scale and translation
// invariance, grazing and degenerate rays, extreme inputs, non-finite samples.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "geometry/spawn.h"
#include "math/rng.h"
#include "math/sampling.h"
#include "render/film.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

using namespace sahara;

namespace {

/// Constant white environment and one lambertian material of the given albedo:
/// a convex object or a plane then reflects exactly `albedo` (one bounce, then
/// the path escapes), so any self-intersection shows as a darker pixel.
SceneDesc furnace(float albedo) {
    SceneDesc d;
    d.source = "<stress>";
    d.background.type = BackgroundDesc::Type::constant;
    d.background.color = Rgb(1.0f);
    MaterialDesc m = default_material();
    m.albedo.color = Rgb(albedo);
    d.materials.push_back(m);
    d.render.width = 24;
    d.render.height = 18;
    d.render.spp = 4;
    d.render.max_depth = 8;
    return d;
}

struct Rendered {
    std::vector<float> rgb;
    std::vector<double> std_error;  ///< per pixel: standard error of the mean luminance
    uint64_t nonfinite;
};

Rendered render(const SceneDesc& desc) {
    const Scene scene = build_scene(desc);
    Film film(desc.render.width, desc.render.height);
    RenderOptions options;
    options.threads = 2;
    const RenderResult r = render_image(scene, film, options);
    std::vector<double> se;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x)
            se.push_back(std::sqrt(film.luminance_variance(x, y) / std::max(1u, film.count(x, y))));
    return {film.to_rgb(), std::move(se), r.nonfinite};
}

/// Camera at `eye` looking at `target` (up +z).
void look(SceneDesc& d, Vec3 eye, Vec3 target, float vfov) {
    d.camera.position = eye;
    d.camera.look_at = target;
    d.camera.up = {0, 0, 1};
    d.camera.vfov = vfov;
}

/// Checks a furnace image: no pixel darker than the albedo (self-shadowing),
/// none brighter than the environment, and the centre pixel equals the albedo.
void check_furnace(const Rendered& r, const SceneDesc& d, float albedo) {
    CHECK(r.nonfinite == 0);
    int dark = 0;
    float lo = 1e9f, hi = -1e9f;
    for (float v : r.rgb) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        dark += v < albedo * (1.0f - 1e-5f);
    }
    INFO("min " << lo << " max " << hi);
    CHECK(dark == 0);
    CHECK(hi <= 1.0f + 1e-5f);
    const size_t c = (size_t(d.render.height / 2) * size_t(d.render.width) + size_t(d.render.width / 2)) * 3;
    CHECK(r.rgb[c] == doctest::Approx(albedo).epsilon(1e-5));
}

Vec3 reflect(const Vec3& v, const Vec3& n) { return v - n * (2.0f * dot(v, n)); }

/// Shoots rays from `eye` at the ground below (down to grazing angles) and, from
/// each hit, spawns shadow rays to lights above and rays into the upper
/// hemisphere. Returns the number of false self-hits (must be 0).
int count_self_hits(const Scene& scene, Vec3 eye, int rays) {
    const Vec3 lights[] = {{0, 0, 10}, {50, -30, 5}, {1e3f, 20, 1}, {-2e4f, 0, 300}};
    Pcg32 rng(17);
    int bad = 0, hits = 0;
    for (int i = 0; i < rays; ++i) {
        // Directions from straight down to 1e-3 above grazing.
        const float dz = -std::pow(10.0f, -3.0f * rng.next_float());
        const float phi = 2.0f * kPi * rng.next_float();
        const float s = std::sqrt(1.0f - dz * dz);
        Ray ray{eye, {s * std::cos(phi), s * std::sin(phi), dz}};
        Hit hit;
        if (!scene.intersect(ray, hit)) continue;
        ++hits;
        const SurfaceInteraction si = scene.interact(ray, hit);
        const Vec3 o = offset_ray_origin(si.p, si.ng);
        for (const Vec3& l : lights) {
            const Vec3 light = eye + l;
            if (dot(light - si.p, si.ng) <= 0) continue;  // light below the tangent plane
            bad += scene.occluded(Ray{o, light - o, 0.0f, 1.0f});
        }
        Ray mirror{o, reflect(ray.dir, si.ng)};
        Hit h2;
        bad += scene.intersect(mirror, h2);
        const Vec3 wi = Frame(si.ng).to_world(sample_cosine_hemisphere({rng.next_float(), rng.next_float()}));
        Ray diffuse{o, wi};
        bad += dot(wi, si.ng) > 0 && scene.intersect(diffuse, h2);
    }
    CHECK(hits > rays / 2);
    return bad;
}

}  // namespace

TEST_CASE("stress: no self-intersection on a plane and on the radius-1e6 ground sphere") {
    const Vec3 origins[] = {{0, 0, 0}, {1e5f, -1e5f, 0}, {3e3f, 0, 0}};
    for (const Vec3& at : origins) {
        for (float height : {1e-3f, 1.7f, 100.0f}) {
            SceneDesc plane;
            plane.planes.push_back({at, {0, 0, 1}, 0});
            SceneDesc ground;
            ground.spheres.push_back({at - Vec3(0, 0, 1e6f), 1e6f, 0, {0, 0, 0}});
            for (const SceneDesc* d : {&plane, &ground}) {
                const Scene scene = build_scene(*d);
                const std::string what = d == &plane ? "plane" : "sphere";
                INFO(what << " origin " << at.x << "," << at.y << " height " << height);
                CHECK(count_self_hits(scene, at + Vec3(0, 0, height), 2000) == 0);
            }
        }
    }
}

TEST_CASE("stress: film counts and drops non-finite samples") {
    Film film(2, 1);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    film.add_sample(0, 0, Rgb(1.0f));
    film.add_sample(0, 0, Rgb(nan, 0, 0));
    film.add_sample(0, 0, Rgb(0, inf, 0));
    film.add_sample(1, 0, Rgb(0, 0, -inf));
    film.add_count(0, 0, 3);
    film.add_count(1, 0, 1);
    CHECK(film.nonfinite_samples() == 3);
    // Dropped samples count as zero radiance: the estimate stays finite (and unbiased
    // if they are rare), never NaN.
    CHECK(film.mean(0, 0).x == doctest::Approx(1.0f / 3.0f));
    CHECK(film.mean(1, 0).z == 0.0f);
}

TEST_CASE("stress: furnace with tiny, huge and far-away spheres") {
    struct Case {
        float radius;
        Vec3 center;
    };
    const Case cases[] = {{1.0f, {0, 0, 0}}, {1e-6f, {0, 0, 0}},         {1e-6f, {1e-3f, 0, 0}},
                          {1e8f, {0, 0, 0}}, {1e5f, {1e7f, 1e7f, 1e7f}}, {10.0f, {1e5f, 0, 0}}};
    for (const Case& c : cases) {
        INFO("radius " << c.radius << " at " << c.center.x);
        SceneDesc d = furnace(0.5f);
        d.spheres.push_back({c.center, c.radius, 0, {0, 0, 0}});
        look(d, c.center + Vec3(0, -3.0f * c.radius, 0), c.center, 50);
        check_furnace(render(d), d, 0.5f);
    }
}

TEST_CASE("stress: furnace with a ground plane and a ground sphere at several scales") {
    for (float scale : {1e-4f, 1.0f, 1e4f}) {
        for (float offset : {0.0f, 1e5f}) {
            INFO("scale " << scale << " offset " << offset);
            const Vec3 at(offset, 0, 0);
            SceneDesc d = furnace(0.5f);
            d.planes.push_back({at, {0, 0, 1}, 0});
            look(d, at + Vec3(0, 0, 1.7f * scale), at + Vec3(0, 10 * scale, 0), 60);
            {
                INFO("plane");
                check_furnace(render(d), d, 0.5f);
            }
            d.planes.clear();
            d.spheres.push_back({at - Vec3(0, 0, 1e6f * scale), 1e6f * scale, 0, {0, 0, 0}});
            check_furnace(render(d), d, 0.5f);
        }
    }
}

namespace {

/// The default scene with every position scaled by `scale` and moved by `offset`.
SceneDesc transformed_default(float scale, Vec3 offset) {
    SceneDesc d = default_scene();
    d.render.width = 40;
    d.render.height = 30;
    d.render.spp = 16;
    d.render.seed = 3;
    for (SphereDesc& s : d.spheres) {
        s.center = s.center * scale + offset;
        s.radius *= scale;
    }
    d.camera.position = d.camera.position * scale + offset;
    d.camera.look_at = d.camera.look_at * scale + offset;
    return d;
}

}  // namespace

TEST_CASE("stress: the default scene renders the same scaled by 1e-4 and 1e4 and moved by 1e5") {
    const Rendered ref = render(transformed_default(1.0f, {0, 0, 0}));
    struct Case {
        float scale;
        Vec3 offset;
    };
    const Case cases[] = {
        {1e-4f, {0, 0, 0}}, {1e4f, {0, 0, 0}}, {1.0f, {1e5f, 0, 0}}, {1.0f, {0, -1e5f, 1e5f}}};
    for (const Case& c : cases) {
        INFO("scale " << c.scale << " offset " << c.offset.x << "," << c.offset.y << "," << c.offset.z);
        const Rendered img = render(transformed_default(c.scale, c.offset));
        CHECK(img.nonfinite == 0);
        // Same seed, same sample streams: pixels differ only where floating-point
        // differences change a path; such a change must stay within the noise.
        int outliers = 0;
        double diff_sum = 0, ref_sum = 0;
        for (size_t i = 0; i < ref.std_error.size(); ++i) {
            const float a = luminance({ref.rgb[3 * i], ref.rgb[3 * i + 1], ref.rgb[3 * i + 2]});
            const float b = luminance({img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]});
            const double sigma =
                std::sqrt(ref.std_error[i] * ref.std_error[i] + img.std_error[i] * img.std_error[i]);
            outliers += std::abs(double(a - b)) > 4.0 * sigma + 1e-3;
            diff_sum += double(b - a);
            ref_sum += double(a);
        }
        INFO("mean relative difference " << diff_sum / ref_sum);
        CHECK(outliers <= int(ref.std_error.size() / 100));
        CHECK(std::abs(diff_sum / ref_sum) < 0.01);
    }
}

TEST_CASE("stress: grazing and tangent rays give no NaN") {
    SceneDesc d;
    d.spheres.push_back({{0, 0, 0}, 1, 0, {0, 0, 0}});
    d.planes.push_back({{0, 0, -1}, {0, 0, 1}, 0});
    const Scene scene = build_scene(d);
    int hits = 0;
    for (int i = -50; i <= 50; ++i) {
        // Rays passing the unit sphere at distance 1 + i * 1e-7 from its centre,
        // and rays along (and barely off) the plane z = -1.
        const float y = 1.0f + float(i) * 1e-7f;
        Ray tangent{{-10, y, 0}, {1, 0, 0}};
        Ray along{{-10, 0, -1.0f + float(i) * 1e-7f}, {1, 0, float(i) * 1e-9f}};
        for (Ray* r : {&tangent, &along}) {
            Hit hit;
            if (!scene.intersect(*r, hit)) continue;
            ++hits;
            REQUIRE(std::isfinite(hit.t));
            const SurfaceInteraction si = scene.interact(*r, hit);
            CHECK(is_finite(si.p));
            CHECK(length(si.ng) == doctest::Approx(1.0f));
            CHECK(dot(si.ng, r->dir) <= 0.0f);
        }
    }
    CHECK(hits > 0);
    // A ray exactly in the plane (0/0) and a ray from the plane parallel to it.
    Ray in_plane{{0, 5, -1}, {1, 0, 0}};
    Hit hit;
    CHECK_FALSE(scene.intersect(in_plane, hit));

    // Rendering the sphere edge-on to a plane through its centre.
    SceneDesc e = furnace(0.5f);
    e.spheres.push_back({{0, 0, 0}, 1, 0, {0, 0, 0}});
    e.planes.push_back({{0, 0, 0}, {0, 0, 1}, 0});
    look(e, {0, -6, 0}, {0, 0, 0}, 30);
    CHECK(render(e).nonfinite == 0);
}

TEST_CASE("stress: extreme depth, albedo and image sizes") {
    SceneDesc d = furnace(1.0f);
    d.spheres.push_back({{0, 0, 0}, 1, 0, {0, 0, 0}});
    look(d, {0, -3, 0}, {0, 0, 0}, 50);
    const size_t centre =
        (size_t(d.render.height / 2) * size_t(d.render.width) + size_t(d.render.width / 2)) * 3;
    SUBCASE("albedo 1 reflects everything, albedo 0 nothing") {
        d.render.max_depth = 1000;
        check_furnace(render(d), d, 1.0f);
        d.materials[0].albedo.color = Rgb(0.0f);
        const Rendered r = render(d);
        CHECK(r.rgb[centre] == 0.0f);
        CHECK(r.rgb[0] == 1.0f);
    }
    SUBCASE("max depth 0 draws nothing, 1 only the background") {
        d.render.max_depth = 0;
        for (float v : render(d).rgb) CHECK(v == 0.0f);
        d.render.max_depth = 1;
        const Rendered r = render(d);
        CHECK(r.rgb[centre] == 0.0f);
        CHECK(r.rgb[0] == 1.0f);
    }
    SUBCASE("1x1 and 16000x1 images") {
        d.render.width = d.render.height = 1;
        const Rendered one = render(d);
        REQUIRE(one.rgb.size() == 3);
        CHECK(one.rgb[0] == doctest::Approx(1.0f));
        d.render.width = 16000;
        d.render.spp = 1;
        const Rendered wide = render(d);
        CHECK(wide.nonfinite == 0);
        REQUIRE(wide.rgb.size() == 16000 * 3);
        CHECK(wide.rgb[8000 * 3] == doctest::Approx(1.0f));
        CHECK(wide.rgb[0] == 1.0f);
    }
}
