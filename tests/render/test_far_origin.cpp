// Scenes far from the world origin render like the same scene at the origin:
// the parser moves everything to a local origin in double before rounding to
// float (io/scene_parser.h, choose_local_origin).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "io/gltf_test_doc.h"
#include "io/scene_parser.h"
#include "render/film.h"
#include "render/renderer.h"
#include "scene/scene.h"

using namespace sahara;
using nlohmann::json;

namespace {

/// A point of the scene at the origin, moved by `offset` (in double, as a user
/// who writes the far-away coordinates into the file would).
json at(const Vec3d& offset, double x, double y, double z) {
    return json::array({offset.x + x, offset.y + y, offset.z + z});
}

/// A small faceted pyramid, written in its own coordinates (placed by the
/// scene's transform, so the OBJ's float digits are not what is tested).
void write_pyramid_obj(const std::filesystem::path& file) {
    std::ofstream out(file);
    out << "v -0.7 -0.7 0\nv 0.7 -0.7 0\nv 0.7 0.7 0\nv -0.7 0.7 0\nv 0.05 0.1 1.3\n"
           "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 4 3 2\n";
}

/// A glTF tetrahedron whose root node carries the whole translation `t`.
void write_gltf(const std::filesystem::path& file, const Vec3d& t) {
    test::gltf::Doc d;
    const std::vector<float> p = {0, 0, 0, 1.1f, 0, 0, 0.3f, 0.9f, 0, 0.4f, 0.35f, 0.8f};
    const std::vector<uint16_t> idx = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
    const int pos = d.positions(p);
    const int ind = d.accessor(idx, 5123, "SCALAR", idx.size());
    d.node({{"mesh", d.mesh(pos, ind)}, {"translation", {t.x, t.y, t.z}}});
    d.write(file);
}

/// Spheres, an OBJ mesh, a glTF mesh, a cylinder, a ground plane, a box, a
/// point light and an emissive sphere (area light), all moved by `offset`.
std::string far_scene(const Vec3d& offset, const std::filesystem::path& dir) {
    write_pyramid_obj(dir / "pyramid.obj");
    write_gltf(dir / "tetra.gltf", offset + Vec3d(1.35, 0.55, 0.0));
    const Vec3d& o = offset;
    json objects = json::array({
        {{"type", "plane"}, {"point", at(o, 0, 0, 0)}, {"normal", {0, 0, 1}}, {"material", "checker"}},
        {{"type", "sphere"}, {"center", at(o, -1.3, 0.4, 0.71)}, {"radius", 0.7}, {"material", "red"}},
        {{"type", "sphere"}, {"center", at(o, 0.45, -1.1, 0.33)}, {"radius", 0.33}, {"material", "metal"}},
        {{"type", "sphere"}, {"center", at(o, 0.3, 1.9, 2.6)}, {"radius", 0.25}, {"material", "lamp"}},
        {{"type", "mesh"},
         {"file", "pyramid.obj"},
         {"material", "green"},
         {"name", "pyramid"},
         {"transform", {{"translate", at(o, -0.2, 1.2, 0)}, {"rotate", {0, 0, 17}}}}},
        // Placed again, turned 90 degrees about the vertical through `o` and
        // shifted by (0.6, -0.2, 0): a rotation whose pivot is far from the
        // world origin, which the local frame must conjugate exactly.
        {{"type", "instance"},
         {"of", "pyramid"},
         {"transform",
          {{"matrix", {0, -1, 0, o.x + o.y + 0.6, 1, 0, 0, o.y - o.x - 0.2, 0, 0, 1, 0, 0, 0, 0, 1}}}}},
        {{"type", "mesh"}, {"file", "tetra.gltf"}, {"material", "red"}},
        {{"type", "cylinder"},
         {"base", at(o, 1.6, -0.4, 0)},
         {"axis", {0.1, 0, 1}},
         {"radius", 0.31},
         {"height", 1.13},
         {"capped", true}},
        {{"type", "box"}, {"min", at(o, -2.4, -1.9, 0)}, {"max", at(o, -1.9, -1.35, 0.45)}},
    });
    json scene = {
        {"render", {{"width", 64}, {"height", 48}, {"spp", 4}, {"max_depth", 4}, {"seed", 5}}},
        {"camera", {{"position", at(o, 0.3, -6.1, 2.7)}, {"look_at", at(o, 0, 0.2, 0.6)}, {"vfov", 42}}},
        {"background", {{"type", "constant"}, {"color", {0.2, 0.25, 0.3}}}},
        {"materials",
         {{"red", {{"type", "lambertian"}, {"albedo", {0.8, 0.2, 0.1}}}},
          {"green", {{"type", "lambertian"}, {"albedo", {0.2, 0.7, 0.2}}}},
          {"metal", {{"type", "metal"}, {"albedo", {0.9, 0.9, 0.9}}, {"roughness", 0.05}}},
          {"lamp", {{"type", "emissive"}, {"radiance", {30, 28, 25}}}},
          {"checker",
           {{"type", "lambertian"},
            {"albedo",
             {{"checker", {{"even", {0.9, 0.9, 0.9}}, {"odd", {0.1, 0.1, 0.1}}, {"scale", 0.5}}}}}}}}},
        {"lights", {{{"type", "point"}, {"position", at(o, -2, -3, 4)}, {"intensity", {20, 20, 20}}}}},
        {"objects", objects}};
    return scene.dump();
}

std::vector<float> render_pixels(const std::string& text, const std::filesystem::path& dir) {
    const SceneDesc desc = parse_scene_json(text, dir / "far.json");
    const Scene scene = build_scene(desc);
    Film film(desc.render.width, desc.render.height);
    RenderOptions options;
    options.threads = 1;
    render_image(scene, film, options);
    return film.to_rgb();
}

/// Fraction of pixels whose colour differs by more than `tolerance` in any channel.
double differing_fraction(const std::vector<float>& a, const std::vector<float>& b, float tolerance) {
    REQUIRE(a.size() == b.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.size(); i += 3) {
        bool d = false;
        for (size_t c = 0; c < 3; ++c) d = d || !(std::abs(a[i + c] - b[i + c]) <= tolerance);
        differ += d;
    }
    return double(differ) / double(a.size() / 3);
}

}  // namespace

TEST_CASE("far origin: the local origin is zero near the world origin and snaps far from it") {
    CHECK(choose_local_origin({0, -800, 300}) == Vec3d(0, 0, 0));
    CHECK(choose_local_origin({1023.9, -1023.9, 0}) == Vec3d(0, 0, 0));
    CHECK(choose_local_origin({1e7 + 0.3, 1e7 - 40, -1e6 + 20}) == Vec3d(1e7, 1e7 - 64, -1e6));
    CHECK(choose_local_origin({1100, 5, -5}) == Vec3d(1088, 0, 0));
}

TEST_CASE("far origin: the scene's positions are stored relative to the camera's grid point") {
    const auto dir = test::gltf::scratch("far_origin_desc");
    const Vec3d offset(1e7, 1e7, 1e7);
    const SceneDesc d = parse_scene_json(far_scene(offset, dir), dir / "far.json");
    CHECK(d.origin == offset);
    // The digits below the float spacing at 1e7 (1.0) survive.
    CHECK(d.camera.position.x == doctest::Approx(0.3).epsilon(1e-6));
    CHECK(d.spheres[0].center.x == doctest::Approx(-1.3).epsilon(1e-6));
    CHECK(d.lights[0].position.z == doctest::Approx(4.0).epsilon(1e-6));
    CHECK(d.boxes[0].hi.z == doctest::Approx(0.45).epsilon(1e-6));
    CHECK(d.planes[0].point == Vec3(0, 0, 0));
    Bounds3 gltf;
    for (const Vec3& p : d.meshes.back().positions) gltf.extend(p);
    CHECK(gltf.lo.x == doctest::Approx(1.35).epsilon(1e-6));
    CHECK(gltf.hi.z == doctest::Approx(0.8).epsilon(1e-6));
}

// Same seed, same sample streams. The offsets are whole numbers so that the
// world-space checker (period 1) lands on the same cells. When the offset is
// a multiple of the origin grid (1e6 and 1e7 are multiples of 64) the local
// coordinates are the origin scene's up to the last bit of the double parse,
// so the image is identical but for rare pixels where a float rounding tipped
// the other way; otherwise the geometry sits up to 32 units from the local
// origin and rounds differently (at most 2^-19 there), which moves a few edge
// samples. Without the local origin the geometry rounds to 1/16 at 1e6 and to
// whole units at 1e7, which moves every edge and the camera.
TEST_CASE("far origin: a scene moved by 1e6 or 1e7 renders like the scene at the origin") {
    const auto dir = test::gltf::scratch("far_origin_render");
    const std::vector<float> ref = render_pixels(far_scene({0, 0, 0}, dir), dir);
    struct Case {
        Vec3d offset;
        double max_fraction;  ///< of pixels differing by more than 1e-3
    };
    const Case cases[] = {{{1e6, 1e6, 1e6}, 0.002},
                          {{1e7, 1e7, 1e7}, 0.002},
                          {{-1e7, 1e7, -1e6}, 0.002},
                          {{1e7 + 21, -1e6 - 45, 1e6 + 9}, 0.02}};
    for (const Case& c : cases) {
        INFO("offset " << c.offset.x << ", " << c.offset.y << ", " << c.offset.z);
        const std::vector<float> img = render_pixels(far_scene(c.offset, dir), dir);
        const double fraction = differing_fraction(ref, img, 1e-3f);
        INFO("differing pixels " << fraction);
        CHECK(fraction <= c.max_fraction);
    }
}

namespace {

/// The pyramid with its vertices written at `o` + the small coordinates, digits
/// enough for double: what a surveyed or georeferenced OBJ looks like.
void write_far_pyramid_obj(const std::filesystem::path& file, const Vec3d& o) {
    const double v[5][3] = {{-0.7, -0.7, 0}, {0.7, -0.7, 0}, {0.7, 0.7, 0}, {-0.7, 0.7, 0}, {0.05, 0.1, 1.3}};
    std::ofstream out(file);
    out.precision(17);
    for (const auto& p : v) out << "v " << o.x + p[0] << " " << o.y + p[1] << " " << o.z + p[2] << "\n";
    out << "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 4 3 2\n";
}

std::string far_obj_scene(const Vec3d& o) {
    json scene = {
        {"render", {{"width", 48}, {"height", 36}, {"spp", 4}, {"max_depth", 3}, {"seed", 2}}},
        {"camera", {{"position", at(o, 0.9, -3.1, 1.9)}, {"look_at", at(o, 0, 0, 0.5)}, {"vfov", 45}}},
        {"background", {{"type", "constant"}, {"color", {0.2, 0.25, 0.3}}}},
        {"lights", {{{"type", "point"}, {"position", at(o, -2, -3, 4)}, {"intensity", {20, 20, 20}}}}},
        {"objects",
         {{{"type", "plane"}, {"point", at(o, 0, 0, 0)}, {"normal", {0, 0, 1}}},
          {{"type", "mesh"}, {"file", "far_pyramid.obj"}}}}};
    return scene.dump();
}

}  // namespace

TEST_CASE("far origin: an OBJ whose vertices sit 1e6 or 1e7 away renders like the OBJ at the origin") {
    // tinyobjloader's double build reads the digits; the loader recentres the model
    // before they round to float. Read in float, the vertices would snap to a grid of
    // 1/16 (1e6) or 1 (1e7) and the pyramid would change shape.
    const auto dir = test::gltf::scratch("far_origin_obj");
    write_far_pyramid_obj(dir / "far_pyramid.obj", {0, 0, 0});
    const std::vector<float> ref = render_pixels(far_obj_scene({0, 0, 0}), dir);
    for (const Vec3d& o : {Vec3d(1e6 + 0.3, -1e6, 2e6), Vec3d(-1e7, 1e7 + 0.7, 1e6)}) {
        INFO("offset " << o.x << ", " << o.y << ", " << o.z);
        write_far_pyramid_obj(dir / "far_pyramid.obj", o);
        const std::vector<float> img = render_pixels(far_obj_scene(o), dir);
        const double fraction = differing_fraction(ref, img, 1e-3f);
        INFO("differing pixels " << fraction);
        CHECK(fraction <= 0.005);
    }
}
