#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/mesh_utils.h"
#include "io/scene_parser.h"
#include "mesh_fixtures.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render/stats.h"
#include "render_test_util.h"
#include "scene/instances.h"
#include "scene/scene.h"

using namespace sahara;
using sahara::test::make_icosphere;

namespace {

/// A scene with a camera looking at the origin from +z and a bright sky.
SceneDesc camera_scene(int w, int h) {
    SceneDesc d;
    d.source = "test";
    d.camera.position = {0, 0, 8};
    d.camera.look_at = {0, 0, 0};
    d.camera.up = {0, 1, 0};
    d.camera.vfov = 50;
    d.background.type = BackgroundDesc::Type::constant;
    d.background.color = Rgb(0.6f, 0.7f, 0.9f);
    d.materials.push_back(default_material());
    d.render.width = w;
    d.render.height = h;
    d.render.spp = 4;
    d.render.max_depth = 3;
    return d;
}

const Mat4 kFirst =
    Mat4::translate({-1.5, 0.3, 0}) * Mat4::rotate_euler({20, 35, 0}) * Mat4::scale({1, 0.6, 1.2});
const Mat4 kSecond =
    Mat4::translate({1.6, -0.4, 1}) * Mat4::rotate_euler({0, -50, 15}) * Mat4::scale({0.7, 1.4, 0.9});

/// An icosphere with vertex normals (the shading normals get tested too).
TriangleMesh smooth_ball() {
    TriangleMesh m = make_icosphere(2);
    for (const Vec3& p : m.positions) m.normals.push_back(normalize(p));
    return m;
}

/// Fraction of pixels whose mean differs by more than `tol` (relative, per channel).
double differing_fraction(const Film& a, const Film& b, double tol) {
    int differ = 0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            const Vec3d pa = a.sum(x, y) / double(a.count(x, y)), pb = b.sum(x, y) / double(b.count(x, y));
            for (int k = 0; k < 3; ++k)
                if (std::abs(pa[k] - pb[k]) > tol * (std::abs(pa[k]) + 1e-3)) {
                    ++differ;
                    break;
                }
        }
    return double(differ) / double(a.width() * a.height());
}

void write_text(const std::filesystem::path& f, const std::string& s) { std::ofstream(f) << s; }

std::filesystem::path scratch(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("sahara_instances_" + name);
    std::filesystem::create_directories(dir);
    return dir;
}

/// A unit square in the z = 0 plane, facing +z, as OBJ text.
const char* kSquareObj = "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3 4\n";

/// Whether a ray from (x, y, 10) straight down -z hits the scene, and where.
std::optional<float> hit_z(const Scene& s, float x, float y) {
    Ray r{{x, y, 10}, {0, 0, -1}};
    Hit h;
    if (!s.intersect(r, h)) return std::nullopt;
    return s.interact(r, h).p.z;
}

}  // namespace

TEST_CASE("instances: an instanced mesh renders the same pixels as the same mesh flattened") {
    // Vertex normals only under similarity transforms: under a non-uniform scale a
    // flattened mesh interpolates normals normalised after the transform, an instance
    // before it, which is a different (equally valid) shading normal, not rounding.
    const Mat4 rigid[2] = {
        Mat4::translate({-1.5, 0.3, 0}) * Mat4::rotate_euler({20, 35, 0}) * Mat4::scale({1.2, 1.2, 1.2}),
        Mat4::translate({1.6, -0.4, 1}) * Mat4::rotate_euler({0, -50, 15})};
    const Mat4 stretched[2] = {kFirst, kSecond};
    for (bool smooth : {false, true})
        for (IntegratorType integrator : {IntegratorType::normals, IntegratorType::path}) {
            const Mat4* place = smooth ? rigid : stretched;
            const TriangleMesh ball = smooth ? smooth_ball() : make_icosphere(2);
            SceneDesc inst = camera_scene(64, 48), flat = camera_scene(64, 48);
            inst.render.integrator = flat.render.integrator = integrator;
            inst.meshes.push_back(ball);
            inst.prototypes.push_back({"ball", {0}});
            for (int k = 0; k < 2; ++k) {
                inst.instances.push_back({0, place[k]});
                TriangleMesh copy = ball;
                transform_mesh(copy, place[k]);
                flat.meshes.push_back(copy);
            }
            const Scene scene = build_scene(inst);
            REQUIRE(scene.instances() != nullptr);
            CHECK(scene.instances()->instance_count() == 2);
            CHECK(scene.triangles.size() == 0);  // nothing copied into the flat tree
            CHECK_FALSE(scene.packets_pay_off());
            Film a(64, 48), b(64, 48);
            test::render_into(inst, a);
            test::render_into(flat, b);
            // Float rounding moves a silhouette sample now and then; nothing else differs.
            CAPTURE(smooth);
            CAPTURE(int(integrator));
            CHECK(differing_fraction(a, b, 1e-3) < 0.01);
            CHECK(differing_fraction(a, b, 0.05) < 0.005);
        }
}

TEST_CASE("instances: the memory estimate counts an instanced mesh once and its trees") {
    const TriangleMesh ball = make_icosphere(2);
    SceneDesc one = camera_scene(8, 8), many = camera_scene(8, 8);
    for (SceneDesc* d : {&one, &many}) {
        d->meshes.push_back(ball);
        d->prototypes.push_back({"ball", {0}});
    }
    one.instances.push_back({0, Mat4::translate({0, 0, 0})});
    for (int k = 0; k < 50; ++k) many.instances.push_back({0, Mat4::translate({double(k), 0, 0})});
    const SceneDesc flat_desc = [&] {
        SceneDesc d = camera_scene(8, 8);
        d.meshes.push_back(ball);
        return d;
    }();
    const Scene a = build_scene(one), b = build_scene(many), flat = build_scene(flat_desc);
    const SceneMemory ma = estimate_scene_memory(a), mb = estimate_scene_memory(b),
                      mf = estimate_scene_memory(flat);
    REQUIRE(mf.triangles > 0);
    CHECK(ma.triangles == mf.triangles);  // the prototype's arrays, once
    CHECK(mb.triangles == mf.triangles);
    CHECK(ma.bvh_estimate > 0);
    CHECK(mb.bvh_estimate > ma.bvh_estimate);  // the top-level tree and the records grow
}

TEST_CASE("instances: shading normals follow the inverse transpose under non-uniform scale") {
    // A square in the plane x + y = 0 (normal (1, 1, 0) / sqrt 2), stretched 2x along x.
    TriangleMesh m;
    const Vec3 n = normalize(Vec3(1, 1, 0));
    m.positions = {{-1, 1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, 1, 1}};
    m.normals.assign(4, n);
    m.indices = {0, 2, 1, 0, 3, 2};  // front face towards +(1, 1, 0)
    SceneDesc d = camera_scene(8, 8);
    d.meshes.push_back(m);
    d.prototypes.push_back({"tilted", {0}});
    d.instances.push_back({0, Mat4::scale({2, 1, 1})});
    const Scene s = build_scene(d);
    // The world plane is x / 2 + y = 0; its normal is (0.5, 1, 0) normalised.
    const Vec3 want = normalize(Vec3(0.5f, 1, 0));
    Ray r{{3, 3, 0.2f}, {-1, -1, 0}};
    Hit h;
    REQUIRE(s.intersect(r, h));
    CHECK(h.instance == 0);
    const SurfaceInteraction si = s.interact(r, h);
    CHECK(std::abs(si.p.x / 2 + si.p.y) < 1e-5f);
    CHECK(si.front_face);
    for (int k = 0; k < 3; ++k) {
        CHECK(si.ng[k] == doctest::Approx(want[k]).epsilon(1e-5));
        CHECK(si.ns[k] == doctest::Approx(want[k]).epsilon(1e-5));
    }
    // Occlusion sees the instance too.
    CHECK(s.occluded(Ray{{3, 3, 0.2f}, {-1, -1, 0}, 0, 10}));
    CHECK_FALSE(s.occluded(Ray{{3, 3, 0.2f}, {-1, -1, 0}, 0, 1}));
    // And so does the shadow cache's form, which remembers no instanced occluder.
    OcclusionCache cache;
    CHECK(s.occluded(Ray{{3, 3, 0.2f}, {-1, -1, 0}, 0, 10}, cache));
    CHECK(cache.owner == nullptr);
    CHECK_FALSE(s.occluded(Ray{{3, 3, 0.2f}, {-1, -1, 0}, 0, 1}, cache));
}

TEST_CASE("instances: the scene format places named meshes and nested instances") {
    const auto dir = scratch("nested");
    write_text(dir / "square.obj", kSquareObj);
    const std::string text = R"({
      "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "up": [0, 1, 0]},
      "objects": [
        {"type": "mesh", "file": "square.obj", "name": "a", "transform": {"translate": [0, 0, 1]}},
        {"type": "instance", "of": "a", "name": "b", "transform": {"translate": [3, 0, 0]}},
        {"type": "instance", "of": "b", "transform": {"translate": [0, 3, 0], "scale": [1, 1, 2]}},
        {"type": "sphere", "center": [-3, -3, 0], "radius": 0.5}
      ]})";
    const SceneDesc d = parse_scene_json(text, dir / "scene.json");
    REQUIRE(d.meshes.size() == 1);
    REQUIRE(d.prototypes.size() == 1);
    REQUIRE(d.instances.size() == 3);  // "a" in place, "b", and the instance of "b"
    const Scene s = build_scene(d);
    // a: z = 1 at the origin; b: z = 1 at x = 3; b's instance: z = 2 at (3, 3).
    CHECK(hit_z(s, 0, 0).value_or(-1) == doctest::Approx(1));
    CHECK(hit_z(s, 3, 0).value_or(-1) == doctest::Approx(1));
    CHECK(hit_z(s, 3, 3).value_or(-1) == doctest::Approx(2));
    CHECK_FALSE(hit_z(s, 0, 3).has_value());
    CHECK(hit_z(s, -3, -3).value_or(-1) == doctest::Approx(0.5));  // the flat tree still works beside
    CHECK(s.bounds().hi.x == doctest::Approx(3.5));
}

TEST_CASE("instances: a name alone changes nothing and bad instances name the problem") {
    const auto dir = scratch("errors");
    write_text(dir / "square.obj", kSquareObj);
    const SceneDesc named = parse_scene_json(
        R"({"camera": {"position": [0, -5, 1], "look_at": [0, 0, 0]},
            "objects": [{"type": "mesh", "file": "square.obj", "name": "a"}]})",
        dir / "scene.json");
    CHECK(named.prototypes.empty());
    CHECK(named.instances.empty());
    CHECK(build_scene(named).instances() == nullptr);
    auto error_of = [&](const std::string& objects) -> std::string {
        try {
            parse_scene_json(
                R"({"camera": {"position": [0, -5, 1], "look_at": [0, 0, 0]}, "objects": )" + objects + "}",
                dir / "scene.json");
        } catch (const std::exception& e) {
            return e.what();
        }
        return "";
    };
    const std::string mesh = R"({"type": "mesh", "file": "square.obj", "name": "a"})";
    CHECK(error_of(R"([{"type": "instance", "of": "nothere"}])").find("nothere") != std::string::npos);
    CHECK(error_of("[" + mesh + R"(, {"type": "instance", "of": "a", "transform": {"scale": [1, 0, 1]}}])")
              .find("objects[1].transform") != std::string::npos);
    CHECK(error_of("[" + mesh + ", " + mesh + "]").find("already names") != std::string::npos);
    CHECK(
        error_of(
            R"([{"type": "sphere", "name": "s", "center": [0, 0, 0], "radius": 1}, {"type": "instance", "of": "s"}])")
            .find("only those can be instanced") != std::string::npos);
}
