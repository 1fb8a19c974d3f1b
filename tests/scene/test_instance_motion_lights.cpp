// Instances that move (motion blur) and instances that emit (light sampling).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/mesh_utils.h"
#include "io/scene_parser.h"
#include "mesh_fixtures.h"
#include "render/film.h"
#include "render/lights.h"
#include "render/renderer.h"
#include "render_test_util.h"
#include "scene/instances.h"
#include "scene/scene.h"
#include "scratch_dir.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A square of side 1 centred at the origin in the z = 0 plane, facing +z.
TriangleMesh square(uint32_t material) {
    TriangleMesh m = unit_grid(1, 0.0f, material);
    for (Vec3& p : m.positions) p -= Vec3(0.5f, 0.5f, 0.0f);
    return m;
}

/// A camera looking down -z at a white square on black, the albedo image.
SceneDesc albedo_scene(float shutter_open, float shutter_close) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.source = "test";
    d.camera.position = {0, 0, 6};
    d.camera.look_at = {0, 0, 0};
    d.camera.up = {0, 1, 0};
    d.camera.vfov = 40;
    d.camera.shutter_open = shutter_open;
    d.camera.shutter_close = shutter_close;
    d.materials.push_back(lambertian(Rgb(0.9f)));
    d.render.width = 40;
    d.render.height = 24;
    d.render.integrator = IntegratorType::albedo;
    d.meshes.push_back(square(1));
    d.prototypes.push_back({"square", {0}});
    return d;
}

/// Mean pixel value (red channel) of a rendered description.
std::vector<double> render_means(const SceneDesc& d, int spp) {
    SceneDesc copy = d;
    copy.render.spp = spp;
    Film film(d.render.width, d.render.height);
    render_into(copy, film);
    std::vector<double> v;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) v.push_back(film.sum(x, y).x / double(film.count(x, y)));
    return v;
}

double mean_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += std::abs(a[i] - b[i]);
    return s / double(a.size());
}

const Vec3 kVelocity{1.6f, 0.4f, 0.0f};
const Mat4 kPlace =
    Mat4::translate({-0.8, 0.1, 0}) * Mat4::rotate_euler({0, 0, 30}) * Mat4::scale({1.2, 0.8, 1});

}  // namespace

TEST_CASE("instance motion: a moving instance at time t sits where its velocity puts it") {
    SceneDesc d = albedo_scene(0, 1);
    d.instances.push_back({0, Mat4::translate({2, 0, 0}), Vec3(0, 3, 0)});
    const Scene s = build_scene(d);
    REQUIRE(s.instances() != nullptr);
    CHECK(s.instances()->has_motion());
    CHECK(s.features.has_motion);
    // Bounds cover the whole path over the shutter.
    CHECK(s.bounds().lo.y <= -0.5f);
    CHECK(s.bounds().hi.y >= 3.5f);
    for (float t : {0.0f, 0.5f, 1.0f}) {
        Ray r{{2, 3 * t + 0.3f, 5}, {0, 0, -1}, 0, kInfinity, t};
        Hit h;
        REQUIRE(s.intersect(r, h));
        const SurfaceInteraction si = s.interact(r, h);
        CHECK(si.p.x == doctest::Approx(2));
        CHECK(si.p.y == doctest::Approx(3 * t + 0.3f));
        CHECK(si.p.z == doctest::Approx(0).epsilon(1e-6));
        // Where the square was at time 0 it is gone by time 1, and the other way round.
        CHECK(s.occluded(Ray{{2, 0.3f, 5}, {0, 0, -1}, 0, 10, t}) == (t < 0.2f));
    }
}

TEST_CASE("instance motion: a moving instance blurs into the mean of its frames") {
    // Motion blur is the time average over the shutter: the moving instance's image
    // must match the mean of still images at evenly spaced times (a flat mesh at
    // each position), up to noise and the frames' spacing.
    SceneDesc moving = albedo_scene(0, 1);
    moving.instances.push_back({0, kPlace, kVelocity});
    const std::vector<double> blurred = render_means(moving, scaled(256));
    const int frames = 16;
    std::vector<double> average(blurred.size(), 0.0);
    std::vector<double> middle;
    for (int k = 0; k < frames; ++k) {
        const float t = (float(k) + 0.5f) / float(frames);
        SceneDesc still = albedo_scene(0, 1);
        still.prototypes.clear();
        TriangleMesh placed = still.meshes[0];
        transform_mesh(placed, Mat4::translate(Vec3d(kVelocity * t)) * kPlace);
        still.meshes[0] = placed;
        const std::vector<double> frame = render_means(still, 16);
        for (size_t i = 0; i < frame.size(); ++i) average[i] += frame[i] / frames;
        if (k == frames / 2) middle = frame;
    }
    const double blur_error = mean_abs_difference(blurred, average);
    const double sharp_error = mean_abs_difference(blurred, middle);
    CAPTURE(blur_error);
    CAPTURE(sharp_error);
    CHECK(blur_error < 0.006);
    CHECK(sharp_error > 3 * blur_error);  // the blur is really there
}

TEST_CASE("instance motion: the scene format's instance velocity composes through nested instances") {
    const auto dir = test::scratch_dir("instance_motion");
    std::ofstream(dir / "square.obj")
        << "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3 4\n";
    const SceneDesc d = parse_scene_json(R"({
      "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "up": [0, 1, 0]},
      "objects": [
        {"type": "mesh", "file": "square.obj", "name": "a"},
        {"type": "instance", "of": "a", "name": "b", "velocity": [1, 0, 0]},
        {"type": "instance", "of": "b", "velocity": [0, 0, 1],
         "transform": {"rotate": [0, 0, 90], "translate": [5, 0, 0]}}
      ]})",
                                         dir / "scene.json");
    REQUIRE(d.instances.size() == 3);
    CHECK(d.instances[0].velocity == Vec3(0.0f));
    CHECK(d.instances[1].velocity == Vec3(1, 0, 0));
    // b's velocity turned by the outer rotation, plus the outer velocity.
    CHECK(d.instances[2].velocity.x == doctest::Approx(0).epsilon(1e-6));
    CHECK(d.instances[2].velocity.y == doctest::Approx(1));
    CHECK(d.instances[2].velocity.z == doctest::Approx(1));
}

namespace {

/// A lambertian floor lit only by a small emissive square 2 above it, facing down;
/// instanced (once, or twice when `second`) or flattened into the scene's own triangles.
SceneDesc lit_floor(bool instanced, bool second,
                    const MaterialDesc& lamp = emissive(Rgb(20.0f, 12.0f, 6.0f))) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.source = "test";
    d.materials.push_back(lambertian(Rgb(0.8f)));
    d.materials.push_back(lamp);
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    const Mat4 place[2] = {
        Mat4::translate({0.3, 0.1, 2}) * Mat4::rotate_euler({180, 0, 20}) * Mat4::scale({0.4, 0.3, 1}),
        Mat4::translate({-0.6, 0.2, 1.5}) * Mat4::rotate_euler({160, 0, 0}) * Mat4::scale({0.3, 0.3, 1})};
    const int count = second ? 2 : 1;
    if (instanced) {
        d.meshes.push_back(square(2));
        d.prototypes.push_back({"lamp", {0}});
        for (int k = 0; k < count; ++k) d.instances.push_back({0, place[k]});
    } else {
        for (int k = 0; k < count; ++k) {
            TriangleMesh m = square(2);
            transform_mesh(m, place[k]);
            d.meshes.push_back(m);
        }
    }
    return d;
}

/// A ray to the floor under both lamps.
const Ray kToFloor{{0, -3, 1}, normalize(Vec3(0, 3, -1)), 0.0f, kInfinity, 0.0f};

/// The instanced scene's estimate `a` against the flat scene's `b`: lit, the same
/// mean, and light sampling, not chance hits (the noise is the flat scene's, not many
/// times it).
void check_sampled_like_flat(const Stat& a, const Stat& b) {
    CAPTURE(a.mean.x);
    CAPTURE(b.mean.x);
    CAPTURE(a.se.x);
    CAPTURE(b.se.x);
    CHECK(a.mean.x > 0.05f);
    CHECK(agree(a, b, 4.0f));
    CHECK(a.se.x < 1.5f * b.se.x);
}

}  // namespace

TEST_CASE("instance lights: an instanced emissive square is light-sampled like the same square flat") {
    for (bool second : {false, true}) {
        const Scene inst = build_scene(lit_floor(true, second));
        const Scene flat = build_scene(lit_floor(false, second));
        REQUIRE(inst.instances() != nullptr);
        CHECK(inst.triangles.size() == 0);
        // Each instance's two triangles are emitters of their own.
        CHECK(inst.emitters.size() == flat.emitters.size());
        CHECK(inst.instanced_emitters.size() == (second ? 4u : 2u));
        CHECK(inst.features.has_area_lights);
        // A hit on the instanced lamp names its emitter (MIS needs it).
        Ray up{{0.3f, 0.1f, 0.5f}, {0, 0, 1}};
        Hit h;
        REQUIRE(inst.intersect(up, h));
        REQUIRE(h.instance == 0);
        CHECK(emitter_of_hit(inst, h) != kNoEmitter);
        // Direct light on the floor (max_depth 2) and one bounce more.
        for (int depth : {2, 3}) {
            CAPTURE(second);
            CAPTURE(depth);
            check_sampled_like_flat(radiance_stats(inst, kToFloor, scaled(20000), depth, 3),
                                    radiance_stats(flat, kToFloor, scaled(20000), depth, 4));
        }
    }
}

TEST_CASE("instance lights: textured emission on an instanced square is sampled like the flat square") {
    // A 2 x 2 texture, bright in one quadrant only: light sampling must look the
    // radiance up at the sampled point's own uv, through the instance's transform.
    auto img = std::make_shared<Image>();
    img->width = img->height = 2;
    img->rgba = {40, 30, 10, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    MaterialDesc lamp = emissive(Rgb(1.0f));
    lamp.radiance.kind = ColorSource::Kind::texture;
    lamp.radiance.texture = 0;
    lamp.radiance.color = Rgb(1.0f);
    SceneDesc inst_desc = lit_floor(true, true, lamp), flat_desc = lit_floor(false, true, lamp);
    for (SceneDesc* d : {&inst_desc, &flat_desc}) d->textures.push_back(TextureDesc{"quadrant", img});
    const Scene inst = build_scene(inst_desc);
    const Scene flat = build_scene(flat_desc);
    REQUIRE(inst.instanced_emitters.size() == 4u);
    const Stat a = radiance_stats(inst, kToFloor, scaled(20000), 2, 3);
    check_sampled_like_flat(a, radiance_stats(flat, kToFloor, scaled(20000), 2, 4));
    // A lamp glowing everywhere like the bright quadrant: the texture really is looked up
    // (a quarter of each lamp is bright, the rest 40 times dimmer).
    const Scene uniform = build_scene(lit_floor(false, true, emissive(Rgb(40.0f, 30.0f, 10.0f))));
    const Stat c = radiance_stats(uniform, kToFloor, scaled(20000), 2, 5);
    CAPTURE(a.mean.x);
    CAPTURE(c.mean.x);
    CHECK(a.mean.x < 0.6f * c.mean.x);
    CHECK(a.mean.x > 0.1f * c.mean.x);
}

TEST_CASE("instance lights: a moving instanced emitter is sampled where it is at the ray's time") {
    SceneDesc d = lit_floor(true, false);
    d.instances[0].velocity = Vec3(5, 0, 0);
    const Scene s = build_scene(d);
    REQUIRE(s.instanced_emitters.size() == 2);
    for (float t : {0.0f, 1.0f}) {
        LightSample ls;
        REQUIRE(sample_light(s, Vec3(0.3f + 5 * t, 0.1f, 0), t, 0.5f, Vec2(0.3f, 0.6f), ls));
        // Straight above the shading point, give or take the square's size.
        CHECK(std::abs(ls.wi.x) < 0.2f);
        CHECK(ls.wi.z > 0.9f);
    }
}
