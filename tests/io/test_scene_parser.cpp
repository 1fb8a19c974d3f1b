#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "io/scene_parser.h"
#include "scene_parser_test_util.h"

using namespace sahara;
using namespace sahara::parser_test;

TEST_CASE("scene parser: default_scene matches the workshop numbers") {
    SceneDesc s = default_scene();
    REQUIRE(s.spheres.size() == 2);
    CHECK(s.spheres[0].center == Vec3(0, 10, 0));
    CHECK(s.spheres[0].radius == 5.0f);
    CHECK(s.spheres[1].center == Vec3(0, 10, -100));
    CHECK(s.spheres[1].radius == 95.0f);
    REQUIRE(s.materials.size() == 3);
    CHECK(s.materials[0].name == default_material().name);
    CHECK(s.materials[0].albedo.color == Rgb(0.5f, 0.5f, 0.5f));
    const Rgb red = s.materials[s.spheres[0].material].albedo.color;
    const Rgb green = s.materials[s.spheres[1].material].albedo.color;
    CHECK((red.x > 0.5f && red.y < 0.3f && red.z < 0.3f));
    CHECK((green.y > 0.5f && green.x < 0.3f && green.z < 0.3f));
    CHECK(s.camera.position == Vec3(0, 0, 0));
    CHECK(s.camera.look_at == Vec3(0, 1, 0));
    CHECK(s.camera.up == Vec3(0, 0, 1));
    CHECK(s.camera.vfov == 90.0f);
    CHECK(s.background.type == BackgroundDesc::Type::gradient);
    CHECK(s.background.bottom == Rgb(1, 1, 1));
    CHECK(s.background.top == Rgb(0.5f, 0.7f, 1.0f));
    CHECK(s.background.up == Vec3(0, 0, 1));
    CHECK(s.render.width == 640);
    CHECK(s.render.height == 480);
    CHECK(s.render.spp == 64);
    CHECK(s.render.max_depth == 8);
}

TEST_CASE("scene parser: minimal scene gets the documented defaults") {
    SceneDesc s = parse_scene_json(kMinimal, "min.json");
    CHECK(s.source == "min.json");
    CHECK(s.render.width == 640);
    CHECK(s.render.integrator == IntegratorType::path);
    CHECK(!s.render.time_limit_s);
    CHECK(s.camera.vfov == 40.0f);
    CHECK(s.camera.up == Vec3(0, 0, 1));
    CHECK(!s.camera.euler_form);
    CHECK(s.background.type == BackgroundDesc::Type::gradient);
    REQUIRE(s.materials.size() == 1);
    CHECK(s.materials[0].name == "default");
    CHECK(s.render.tonemap == Tonemap::clamp);
    CHECK(s.render.exposure == 0.0f);
    CHECK(s.render.bvh_builder == kDefaultBvhBuilder);
}

TEST_CASE("scene parser: every key round-trips into SceneDesc") {
    ScratchDir scratch;
    FakeLoaders fake;
    const std::string text = R"({
      "format": "scene/1",
      "render": { "width": 320, "height": 200, "spp": 16, "max_depth": 5, "seed": 18446744073709551615,
                  "integrator": "bvh-cost", "time_limit_s": 2.5, "target_error": 0.01,
                  "exposure": -1.5, "tonemap": "aces", "bvh_builder": "reinsert" },
      "camera": { "position": [0, -6, 1.5], "look_at": [0, 0, 1], "up": [0, 0, 2], "vfov": 40,
                  "aperture": 0.1, "focus_distance": 5, "shutter": [0.25, 0.75] },
      "background": { "type": "envmap", "file": "sky.exr", "strength": 2, "up": [0, 1, 0] },
      "materials": {
        "white":  { "type": "lambertian", "albedo": [0.73, 0.73, 0.73] },
        "floor":  { "type": "lambertian", "albedo": { "checker": { "even": [0.9, 0.8, 0.7], "odd": [0.1, 0.2, 0.3], "scale": 2.0 } } },
        "wood":   { "type": "lambertian", "albedo": { "texture": "textures/wood.png" } },
        "leaf":   { "type": "lambertian", "albedo": { "texture": "textures/wood.png" },
                    "alpha": { "texture": "textures/leaf.png" }, "alpha_cutoff": 0.4 },
        "veil":   { "type": "lambertian", "alpha": 0.25 },
        "chrome": { "type": "metal", "albedo": [0.9, 0.9, 0.9], "roughness": 0.2 },
        "glass":  { "type": "dielectric", "ior": 1.33 },
        "lamp":   { "type": "emissive", "radiance": [10, 20, 30] }
      },
      "objects": [
        { "type": "sphere", "center": [0, 0, 1], "radius": 1, "material": "white" },
        { "type": "sphere", "center": [2, 0, 1], "radius": 0.5, "material": "glass", "velocity": [0, 0, 0.5] },
        { "type": "plane",  "point": [0, 0, -1], "normal": [0, 0, 3], "material": "floor" },
        { "type": "box",    "min": [-3, -1, 0], "max": [-2, 0, 1], "material": "chrome" },
        { "type": "mesh",   "file": "meshes/thing.obj", "material": "white",
          "transform": { "scale": 10, "rotate": [90, 0, 0], "translate": [0, 1, 0] } },
        { "type": "mesh",   "file": "meshes/thing.obj" },
        { "type": "ellipsoid", "center": [1, 2, 3], "radii": [1, 2, 4], "material": "lamp" },
        { "type": "cylinder", "base": [0, 0, 0], "axis": [0, 0, 5], "radius": 0.5, "height": 2, "capped": true },
        { "type": "cone", "apex": [0, 0, 3], "axis": [0, 0, -1], "angle": 45, "height": 2, "capped": true },
        { "type": "paraboloid", "vertex": [0, 0, 0], "axis": [1, 0, 0], "radius": 2, "height": 4 },
        { "type": "hyperboloid", "center": [0, 0, 0], "axis": [0, 0, 1], "radius": 2, "waist": 1, "height": 2,
          "transform": { "translate": [0, 0, 10] } },
        { "type": "quadric", "coefficients": [1, 1, 1, 0, 0, 0, 0, 0, 0, -1],
          "bounds": { "min": [-1, -1, -1], "max": [1, 1, 0] }, "material": "veil" }
      ],
      "lights": [
        { "type": "point", "position": [-1.3, 8.4, 0], "intensity": [20, 20, 20] },
        { "type": "directional", "direction": [0, 0, -2], "irradiance": [3, 3, 3] }
      ]
    })";
    SceneDesc s = parse_scene_json(text, scratch.dir / "all.json", fake.loaders());

    const RenderSettings& r = s.render;
    CHECK(r.width == 320);
    CHECK(r.height == 200);
    CHECK(r.spp == 16);
    CHECK(r.max_depth == 5);
    CHECK(r.seed == 18446744073709551615ull);
    CHECK(r.integrator == IntegratorType::bvh_cost);
    CHECK(r.time_limit_s == 2.5);
    CHECK(r.target_error == 0.01);
    CHECK(r.exposure == -1.5f);
    CHECK(r.tonemap == Tonemap::aces);
    CHECK(r.bvh_builder == BvhBuilder::reinsert);

    const CameraDesc& c = s.camera;
    CHECK(c.position == Vec3(0, -6, 1.5f));
    CHECK(c.look_at == Vec3(0, 0, 1));
    CHECK(c.up == Vec3(0, 0, 1));  // normalised
    CHECK(c.vfov == 40.0f);
    CHECK(c.aperture == 0.1f);
    CHECK(c.focus_distance == 5.0f);
    CHECK(c.shutter_open == 0.25f);
    CHECK(c.shutter_close == 0.75f);

    CHECK(s.background.type == BackgroundDesc::Type::envmap);
    CHECK(s.background.strength == 2.0f);
    CHECK(s.background.up == Vec3(0, 1, 0));
    CHECK(fs::path(s.background.file) == scratch.dir / "sky.exr");
    REQUIRE(s.background.image);
    CHECK(s.background.image->width == 2);  // read linear (srgb_to_linear = false)

    // materials: default first, then the file's order; the model's two at the end
    REQUIRE(s.materials.size() == 1 + 8 + 2);
    const char* names[] = {"default", "white", "floor", "wood", "leaf", "veil", "chrome", "glass", "lamp"};
    for (size_t i = 0; i < 9; ++i) CHECK(s.materials[i].name == names[i]);
    CHECK(s.materials[1].albedo.color == Rgb(0.73f, 0.73f, 0.73f));
    const ColorSource& floor = s.materials[2].albedo;
    CHECK(floor.kind == ColorSource::Kind::checker);
    CHECK(floor.even == Rgb(0.9f, 0.8f, 0.7f));
    CHECK(floor.odd == Rgb(0.1f, 0.2f, 0.3f));
    CHECK(floor.checker_scale == 2.0f);
    // textures: wood (sRGB) once, shared by "wood" and "leaf"; leaf alpha (linear); then the model's
    REQUIRE(s.textures.size() == 3);
    CHECK(s.materials[3].albedo.kind == ColorSource::Kind::texture);
    CHECK(s.materials[3].albedo.texture == 0);
    CHECK(s.materials[4].albedo.texture == 0);
    CHECK(s.textures[0].image->width == 1);
    CHECK(s.materials[4].alpha_texture == 1);
    CHECK(s.textures[1].image->width == 2);
    CHECK(s.materials[4].alpha_cutoff == 0.4f);
    CHECK(s.materials[5].alpha == 0.25f);
    CHECK(!s.materials[5].alpha_cutoff);
    CHECK(s.materials[6].type == MaterialType::metal);
    CHECK(s.materials[6].roughness == 0.2f);
    CHECK(s.materials[7].type == MaterialType::dielectric);
    CHECK(s.materials[7].ior == 1.33f);
    CHECK(s.materials[8].type == MaterialType::emissive);
    CHECK(s.materials[8].radiance.color == Rgb(10, 20, 30));

    REQUIRE(s.spheres.size() == 2);
    CHECK(s.spheres[0].material == 1);
    CHECK(s.spheres[1].velocity == Vec3(0, 0, 0.5f));
    CHECK(s.spheres[1].material == 7);
    REQUIRE(s.planes.size() == 1);
    CHECK(s.planes[0].normal == Vec3(0, 0, 1));
    CHECK(s.planes[0].point == Vec3(0, 0, -1));
    CHECK(s.planes[0].material == 2);
    REQUIRE(s.boxes.size() == 1);
    CHECK(s.boxes[0].lo == Vec3(-3, -1, 0));
    CHECK(s.boxes[0].hi == Vec3(-2, 0, 1));
    CHECK(s.boxes[0].material == 6);

    // meshes: the first overrides the material, the second keeps the file's (shifted)
    REQUIRE(s.meshes.size() == 2);
    CHECK(s.meshes[0].material == 1);
    CHECK(s.meshes[0].material_ids.empty());
    CHECK(s.meshes[1].material_ids == std::vector<uint32_t>{9, 10});
    CHECK(s.materials[9].albedo.texture == 2);
    CHECK(s.materials[10].alpha_texture == 2);
    REQUIRE(fake.model_transforms.size() == 2);
    Mat4 expected = Mat4::translate({0, 1, 0}) * Mat4::rotate_euler({90, 0, 0}) * Mat4::scale({10, 10, 10});
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            CHECK(fake.model_transforms[0].m[i][j] == doctest::Approx(expected.m[i][j]));
    CHECK(s.lights.size() == 2 + 2);  // the scene's two, then one from each mesh's model

    REQUIRE(s.quadrics.size() == 6);
    const QuadricDesc& e = s.quadrics[0];
    CHECK(e.type == QuadricDesc::Type::ellipsoid);
    CHECK(e.origin == Vec3(1, 2, 3));
    CHECK(e.radii == Vec3(1, 2, 4));
    CHECK(e.material == 8);
    CHECK(e.coefficients[1] == doctest::Approx(0.25));
    CHECK(near(e.world_bounds.lo, Vec3(0, 0, -1)));
    CHECK(near(e.world_bounds.hi, Vec3(2, 4, 7)));
    const QuadricDesc& cyl = s.quadrics[1];
    CHECK(cyl.type == QuadricDesc::Type::cylinder);
    CHECK(cyl.axis == Vec3(0, 0, 1));
    CHECK(cyl.radius == 0.5f);
    CHECK(cyl.height == 2.0f);
    CHECK(cyl.capped);
    CHECK(s.quadrics[2].type == QuadricDesc::Type::cone);
    CHECK(s.quadrics[2].angle == 45.0f);
    CHECK(s.quadrics[2].origin == Vec3(0, 0, 3));
    CHECK(s.quadrics[2].capped);
    CHECK(s.quadrics[3].type == QuadricDesc::Type::paraboloid);
    CHECK(s.quadrics[3].axis == Vec3(1, 0, 0));
    CHECK(s.quadrics[4].type == QuadricDesc::Type::hyperboloid);
    CHECK(s.quadrics[4].waist == 1.0f);
    CHECK(near(s.quadrics[4].world_bounds.lo, Vec3(-2, -2, 9)));
    const QuadricDesc& g = s.quadrics[5];
    CHECK(g.type == QuadricDesc::Type::general);
    CHECK(g.coefficients[9] == -1.0);
    CHECK(g.local_bounds.hi == Vec3(1, 1, 0));
    CHECK(g.material == 5);

    CHECK(s.lights[0].type == LightDesc::Type::point);
    CHECK(s.lights[0].position == Vec3(-1.3f, 8.4f, 0));
    CHECK(s.lights[0].intensity == Rgb(20, 20, 20));
    CHECK(s.lights[1].type == LightDesc::Type::directional);
    CHECK(s.lights[1].direction == Vec3(0, 0, -1));
    CHECK(s.lights[1].irradiance == Rgb(3, 3, 3));
}

TEST_CASE("scene parser: the euler camera form") {
    SceneDesc s = parse_scene_json(
        R"({"camera": {"position": [0, 5, -8], "euler": [20, 10, 5], "focal_length": 1.5, "aperture": 0.1},
            "objects": []})",
        "e.json");
    CHECK(s.camera.euler_form);
    CHECK(s.camera.position == Vec3(0, 5, -8));
    CHECK(s.camera.euler == Vec3(20, 10, 5));
    CHECK(s.camera.focal_length == 1.5f);
    CHECK(s.camera.aperture == 0.1f);
    CHECK(s.camera.focus_distance == 1.5f);
}

TEST_CASE("scene parser: transforms apply scale, then rotate, then translate") {
    SceneDesc s = parse_scene_json(with_objects(R"([
        { "type": "sphere", "center": [1, 0, 0], "radius": 1,
          "transform": { "scale": 2, "rotate": [0, 0, 90], "translate": [0, 0, 5] } },
        { "type": "ellipsoid", "center": [0, 0, 0], "radii": [1, 1, 1],
          "transform": { "scale": [1, 2, 3], "rotate": [90, 0, 0], "translate": [1, 0, 0] } },
        { "type": "ellipsoid", "transform": { "matrix": [0, -1, 0, 4,  1, 0, 0, 5,  0, 0, 1, 6,  0, 0, 0, 1] } },
        { "type": "plane", "point": [0, 0, 1], "normal": [0, 0, 1], "transform": { "rotate": [90, 0, 0] } }
    ])"),
                                   "t.json");
    // S: (2,0,0); R about Z by 90: (0,2,0); T: (0,2,5). Any other order lands elsewhere.
    CHECK(near(s.spheres[0].center, Vec3(0, 2, 5)));
    CHECK(s.spheres[0].radius == doctest::Approx(2.0f));
    // (1,1,1) -> S (1,2,3) -> Rx(90) (1,-3,2) -> T (2,-3,2)
    CHECK(near(s.quadrics[0].world_from_local.apply_point(Vec3(1, 1, 1)), Vec3(2, -3, 2)));
    CHECK(near(s.quadrics[0].local_from_world.apply_point(Vec3(2, -3, 2)), Vec3(1, 1, 1)));
    // row-major matrix: x -> y, plus translation (4, 5, 6)
    CHECK(near(s.quadrics[1].world_from_local.apply_point(Vec3(1, 0, 0)), Vec3(4, 6, 6)));
    // the plane's point and normal rotate together: z -> -y
    CHECK(near(s.planes[0].point, Vec3(0, -1, 0)));
    CHECK(near(s.planes[0].normal, Vec3(0, -1, 0)));
}

TEST_CASE("scene parser: transformed boxes stay boxes or become outward-facing meshes") {
    SceneDesc s = parse_scene_json(with_objects(R"([
        { "type": "box", "min": [0, 0, 0], "max": [1, 2, 3], "transform": { "rotate": [0, 0, 90], "translate": [10, 0, 0] } },
        { "type": "box", "min": [0, 0, 0], "max": [1, 2, 3], "transform": { "rotate": [0, 0, 30] } },
        { "type": "box", "min": [0, 0, 0], "max": [1, 2, 3], "transform": { "scale": [-1, 1, 1], "rotate": [10, 0, 0] } }
    ])"),
                                   "b.json");
    REQUIRE(s.boxes.size() == 1);
    CHECK(near(s.boxes[0].lo, Vec3(8, 0, 0)));
    CHECK(near(s.boxes[0].hi, Vec3(10, 1, 3)));
    REQUIRE(s.meshes.size() == 2);
    for (const TriangleMesh& m : s.meshes) {
        REQUIRE(m.triangle_count() == 12);
        Vec3 center(0.0f);
        for (const Vec3& p : m.positions) center += p * (1.0f / float(m.positions.size()));
        for (size_t t = 0; t < m.triangle_count(); ++t) {
            Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                 c = m.positions[m.indices[3 * t + 2]];
            Vec3 n = cross(b - a, c - a);
            CHECK(dot(n, (a + b + c) * (1.0f / 3.0f) - center) >
                  0.0f);  // counter-clockwise seen from outside
        }
    }
}

TEST_CASE("scene parser: quadric canonical forms pass through their named surfaces") {
    SceneDesc s = parse_scene_json(with_objects(R"([
        { "type": "cylinder", "base": [1, 2, 3], "axis": [1, 1, 0], "radius": 0.5, "height": 2 },
        { "type": "cone", "apex": [0, 0, 1], "axis": [0, 0, -1], "angle": 30, "height": 2 },
        { "type": "paraboloid", "vertex": [0, 1, 0], "axis": [0, -1, 0.5], "radius": 2, "height": 3 },
        { "type": "hyperboloid", "center": [2, 0, 0], "axis": [0, 1, 0], "radius": 2, "waist": 1, "height": 4 }
    ])"),
                                   "q.json");
    REQUIRE(s.quadrics.size() == 4);
    auto eval = [](const QuadricDesc& q, const Vec3& world) {
        Vec3d p(q.local_from_world.apply_point(world));
        const auto& c = q.coefficients;
        return c[0] * p.x * p.x + c[1] * p.y * p.y + c[2] * p.z * p.z + c[3] * p.x * p.y + c[4] * p.x * p.z +
               c[5] * p.y * p.z + c[6] * p.x + c[7] * p.y + c[8] * p.z + c[9];
    };
    auto perp = [](const Vec3& axis) {
        return normalize(cross(axis, std::abs(axis.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
    };
    auto inside = [](const QuadricDesc& q, const Vec3& world) {
        Bounds3 b = q.local_bounds;
        b.lo -= Vec3(1e-4f);
        b.hi += Vec3(1e-4f);
        return b.contains(q.local_from_world.apply_point(world));
    };
    for (const QuadricDesc& q : s.quadrics) {
        Vec3 a = q.axis, n = perp(a);
        float t = std::tan(q.angle * float(std::numbers::pi) / 180.0f);
        std::vector<Vec3> on;  // points the named form says are on the surface
        switch (q.type) {
            case QuadricDesc::Type::cylinder:
                on = {q.origin + n * q.radius, q.origin + a * q.height + n * q.radius};
                break;
            case QuadricDesc::Type::cone:
                on = {q.origin, q.origin + a * q.height + n * (q.height * t)};
                break;
            case QuadricDesc::Type::paraboloid:
                on = {q.origin, q.origin + a * q.height + n * q.radius};
                break;
            default:
                on = {q.origin + n * q.waist, q.origin + a * (0.5f * q.height) + n * q.radius};
                break;
        }
        for (const Vec3& p : on) {
            CAPTURE(int(q.type));
            CHECK(eval(q, p) == doctest::Approx(0.0).epsilon(1e-5));
            CHECK(inside(q, p));
        }
        CHECK(std::abs(eval(q, q.origin + a * (0.5f * q.height) + n * 10.0f)) > 1e-3);  // off the surface
    }
}

TEST_CASE("scene parser: files") {
    ScratchDir scratch;
    const fs::path missing = scratch.dir / "missing.json";
    try {
        parse_scene_file(missing);
        FAIL("no error for a missing file");
    } catch (const InputError& e) {
        std::string msg = e.what();
        CHECK(msg.find("missing.json") != std::string::npos);
        CHECK(msg.find("cannot open scene file") != std::string::npos);
    }
    CHECK_THROWS_WITH_AS(parse_scene_file(scratch.dir), doctest::Contains("is a directory"), InputError);
    // paths inside a scene resolve against the scene file's directory, not the working directory
    const fs::path scene = scratch.dir / "s.json";
    std::ofstream(scene) << with_objects(R"([{"type": "mesh", "file": "meshes/thing.obj"}])");
    try {
        parse_scene_file(scene);  // the real loader cannot read the stand-in file either way
        FAIL("the stand-in mesh file loaded");
    } catch (const InputError& e) {
        std::string msg = e.what();
        CAPTURE(msg);
        CHECK(msg.find("objects[0].file") != std::string::npos);
        CHECK(msg.find((scratch.dir / "meshes" / "thing.obj").string()) != std::string::npos);
    }
}

TEST_CASE("scene parser: merge_loaded_model shifts indices or overrides the material") {
    SceneDesc s = default_scene();
    s.textures.resize(2);
    LoadedModel m;
    TriangleMesh mesh;
    mesh.indices = {0, 1, 2};
    mesh.material = 1;
    m.meshes = {mesh, mesh};
    m.meshes[1].material_ids = {1};
    MaterialDesc tex;
    tex.albedo.texture = 0;
    tex.radiance.texture = 0;
    m.materials = {MaterialDesc{}, tex};
    m.textures.resize(1);
    LoadedModel copy = m;
    merge_loaded_model(s, std::move(m), std::nullopt);
    REQUIRE(s.materials.size() == 5);
    REQUIRE(s.textures.size() == 3);
    CHECK(s.materials[4].albedo.texture == 2);
    CHECK(s.materials[4].radiance.texture == 2);
    CHECK(s.materials[3].albedo.texture == -1);
    CHECK(s.meshes[0].material == 4);
    CHECK(s.meshes[1].material_ids == std::vector<uint32_t>{4});
    merge_loaded_model(s, std::move(copy), 1u);
    CHECK(s.materials.size() == 5);
    CHECK(s.textures.size() == 3);
    CHECK(s.meshes[3].material == 1);
    CHECK(s.meshes[3].material_ids.empty());
}

TEST_CASE("scene parser: every shipped scene parses") {
    const fs::path dir = fs::path(SAHARA_SOURCE_DIR) / "scenes";
    int count = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".json") continue;
        CAPTURE(entry.path().string());
        SceneDesc s;
        CHECK_NOTHROW(s = parse_scene_file(entry.path()));
        CHECK(s.materials.size() >= 1);
        ++count;
    }
    CHECK(count >= 3);
}

TEST_CASE("scene parser: workshop.json is the built-in default scene") {
    SceneDesc f = parse_scene_file(fs::path(SAHARA_SOURCE_DIR) / "scenes" / "workshop.json");
    SceneDesc d = default_scene();
    REQUIRE(f.spheres.size() == d.spheres.size());
    for (size_t i = 0; i < d.spheres.size(); ++i) {
        CHECK(f.spheres[i].center == d.spheres[i].center);
        CHECK(f.spheres[i].radius == d.spheres[i].radius);
        CHECK(f.materials[f.spheres[i].material].albedo.color ==
              d.materials[d.spheres[i].material].albedo.color);
    }
    CHECK(f.camera.position == d.camera.position);
    CHECK(f.camera.look_at == d.camera.look_at);
    CHECK(f.camera.vfov == d.camera.vfov);
    CHECK(f.background.top == d.background.top);
    CHECK(f.render.spp == d.render.spp);
    CHECK(f.render.width == d.render.width);
}

TEST_CASE("scene parser: directions of any finite length give unit vectors") {
    const SceneDesc s = parse_scene_json(
        R"({"camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "up": [0, 0, 1e-30]},
            "background": {"type": "gradient", "up": [1e30, 0, 0]},
            "objects": [{"type": "plane", "normal": [0, 3e38, 3e38]},
                        {"type": "cylinder", "axis": [1e-38, 0, 0]}],
            "lights": [{"type": "directional", "direction": [1e30, 0, 1e30]}]})",
        "dirs.json");
    const auto unit = [](Vec3 v) { return std::abs(length(v) - 1.0f) < 1e-5f; };
    CHECK(unit(s.camera.up));
    CHECK(unit(s.background.up));
    REQUIRE(s.planes.size() == 1);
    CHECK(unit(s.planes[0].normal));
    REQUIRE(s.quadrics.size() == 1);
    CHECK(s.quadrics[0].axis == Vec3(1, 0, 0));
    REQUIRE(s.lights.size() == 1);
    CHECK(s.lights[0].direction.x == doctest::Approx(std::sqrt(0.5)));
    CHECK(s.lights[0].direction.z == doctest::Approx(std::sqrt(0.5)));
}

TEST_CASE("scene parser: an unlit material takes a colour source and the cut-out keys") {
    ScratchDir scratch;
    FakeLoaders fake;
    const SceneDesc s = parse_scene_json(
        R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0]},
            "materials": {
              "sign":  {"type": "unlit", "color": [0.2, 0.4, 0.6]},
              "white": {"type": "unlit"},
              "photo": {"type": "unlit", "color": {"texture": "textures/wood.png"},
                        "alpha": {"texture": "textures/leaf.png"}, "alpha_cutoff": 0.3},
              "tiles": {"type": "unlit", "color": {"checker": {"scale": 2}}, "alpha": 0.5}},
            "objects": []})",
        scratch.dir / "unlit.json", fake.loaders());
    REQUIRE(s.materials.size() == 5);
    for (size_t i = 1; i < 5; ++i) CHECK(s.materials[i].type == MaterialType::unlit);
    CHECK(s.materials[1].albedo.kind == ColorSource::Kind::constant);
    CHECK(s.materials[1].albedo.color == Rgb(0.2f, 0.4f, 0.6f));
    CHECK(s.materials[2].albedo.color == Rgb(1.0f));  // glTF's default base colour
    CHECK(s.materials[3].albedo.kind == ColorSource::Kind::texture);
    CHECK(s.materials[3].albedo.texture == 0);
    CHECK(s.materials[3].alpha_texture == 1);
    CHECK(s.materials[3].alpha_cutoff == 0.3f);
    REQUIRE(fake.images.size() == 2);
    CHECK(fake.images[0] == std::make_pair(std::string("wood.png"), true));   // colour: sRGB
    CHECK(fake.images[1] == std::make_pair(std::string("leaf.png"), false));  // alpha: linear
    CHECK(s.materials[4].albedo.kind == ColorSource::Kind::checker);
    CHECK(s.materials[4].albedo.checker_scale == 2.0f);
    CHECK(s.materials[4].alpha == 0.5f);
    CHECK(!s.materials[4].alpha_cutoff);
}

TEST_CASE("a model joining a scene with textures has every texture slot renumbered") {
    SceneDesc scene;
    scene.textures.resize(3);  // the scene's own textures come first
    LoadedModel model;
    model.textures.resize(13);
    MaterialDesc m;
    m.albedo.kind = ColorSource::Kind::texture;
    m.albedo.texture = 0;
    m.metallic_roughness_texture = 1;
    m.normal_texture = 2;
    m.radiance.kind = ColorSource::Kind::texture;
    m.radiance.texture = 3;
    m.transmission_texture = 4;
    m.specular_texture = 5;
    m.specular_color_texture = 6;
    m.layers.clearcoat_texture = 7;
    m.layers.clearcoat_roughness_texture = 8;
    m.layers.clearcoat_normal_texture = 9;
    m.layers.sheen_color_texture = 10;
    m.layers.sheen_roughness_texture = 11;
    m.alpha_texture = 12;
    model.materials.push_back(m);
    merge_loaded_model(scene, std::move(model), std::nullopt);
    REQUIRE(scene.materials.size() == 1);
    REQUIRE(scene.textures.size() == 16);
    const MaterialDesc& out = scene.materials[0];
    CHECK(out.albedo.texture == 3);
    CHECK(out.metallic_roughness_texture == 4);
    CHECK(out.normal_texture == 5);
    CHECK(out.radiance.texture == 6);
    CHECK(out.transmission_texture == 7);
    CHECK(out.specular_texture == 8);
    CHECK(out.specular_color_texture == 9);
    CHECK(out.layers.clearcoat_texture == 10);
    CHECK(out.layers.clearcoat_roughness_texture == 11);
    CHECK(out.layers.clearcoat_normal_texture == 12);
    CHECK(out.layers.sheen_color_texture == 13);
    CHECK(out.layers.sheen_roughness_texture == 14);
    CHECK(out.alpha_texture == 15);
}
