// The up-axis rule of `sahara view` for OBJ files (io/up_axis.h, docs/view.md),
// one generated model per case of the rule.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "io/model_loader.h"
#include "io/up_axis.h"
#include "io/view_scene.h"
#include "scratch_dir.h"

using namespace sahara;
namespace fs = std::filesystem;

namespace {

/// An OBJ being written: vertices and polygons (counter-clockwise from outside).
struct ObjText {
    std::vector<Vec3> v;
    std::vector<std::vector<int>> faces;

    void polygon(std::initializer_list<Vec3> corners) {
        std::vector<int> f;
        for (const Vec3& p : corners) {
            v.push_back(p);
            f.push_back(int(v.size()));
        }
        faces.push_back(f);
    }
    void box(Vec3 lo, Vec3 hi) {
        const auto p = [&](int i) {
            return Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        };
        polygon({p(0), p(2), p(3), p(1)});  // -z
        polygon({p(4), p(5), p(7), p(6)});  // +z
        polygon({p(0), p(1), p(5), p(4)});  // -y
        polygon({p(2), p(6), p(7), p(3)});  // +y
        polygon({p(0), p(4), p(6), p(2)});  // -x
        polygon({p(1), p(3), p(7), p(5)});  // +x
    }
    /// Applies `f` to every vertex (to turn or move the model).
    void map(const std::function<Vec3(Vec3)>& f) {
        for (Vec3& p : v) p = f(p);
    }
    fs::path write(const std::string& name, const std::string& header = "") const {
        const fs::path dir = test::scratch_dir("up_axis");
        const fs::path file = dir / name;
        std::ofstream out(file);
        out << header;
        for (const Vec3& p : v) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
        for (const auto& f : faces) {
            out << 'f';
            for (int i : f) out << ' ' << i;
            out << '\n';
        }
        return file;
    }
};

/// A figure standing along +y with its arms spread: 2 wide, 2.35 tall, 0.6
/// deep (as flat as a T-pose gets), its feet at y = -1.2 (not on a zero plane).
ObjText y_up_figure() {
    ObjText o;
    o.box({-0.3f, 1.0f, -0.3f}, {0.3f, 2.0f, 0.3f});       // torso
    o.box({-0.15f, 2.0f, -0.15f}, {0.15f, 2.35f, 0.15f});  // head
    o.box({-0.25f, 0.0f, -0.15f}, {-0.05f, 1.0f, 0.15f});  // legs
    o.box({0.05f, 0.0f, -0.15f}, {0.25f, 1.0f, 0.15f});
    o.box({-1.0f, 1.75f, -0.1f}, {-0.3f, 1.95f, 0.1f});  // arms
    o.box({0.3f, 1.75f, -0.1f}, {1.0f, 1.95f, 0.1f});
    o.map([](Vec3 p) { return p - Vec3(0, 1.2f, 0); });
    return o;
}

/// The same figure turned to stand along +z (facing -y), its feet at z = `feet`.
ObjText z_up_figure(float feet) {
    ObjText o = y_up_figure();
    o.map([feet](Vec3 p) { return Vec3(p.x, -p.z, p.y + 1.2f + feet); });
    return o;
}

/// A house from a Z-up tool: a 12 x 10 floor slab, walls flush with it, a door
/// frame standing out of the front, a pitched roof; 5 tall, so not flat. It
/// sits at z = 2 (not on a zero plane).
ObjText z_up_house() {
    ObjText o;
    o.box({-6, -5, 0}, {6, 5, 0.3f});
    o.box({-6, -5, 0.3f}, {6, -4.8f, 3});
    o.box({-6, 4.8f, 0.3f}, {6, 5, 3});
    o.box({-6, -4.8f, 0.3f}, {-5.8f, 4.8f, 3});
    o.box({5.8f, -4.8f, 0.3f}, {6, 4.8f, 3});
    o.box({-1, -5.1f, 0.3f}, {1, -4.7f, 2.2f});
    o.polygon({{-6, -5, 3}, {6, -5, 3}, {6, 0, 5}, {-6, 0, 5}});
    o.polygon({{6, 5, 3}, {-6, 5, 3}, {-6, 0, 5}, {6, 0, 5}});
    o.map([](Vec3 p) { return p + Vec3(0, 0, 2); });
    return o;
}

/// Rolling terrain, 10 x 10 and about 1.2 high along z, no flat faces at its bottom.
ObjText z_up_terrain() {
    ObjText o;
    const auto h = [](float x, float y) { return 3.0f + 0.6f * std::sin(x) * std::cos(0.8f * y); };
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) {
            const float x0 = -5 + 0.5f * float(i), y0 = -5 + 0.5f * float(j), x1 = x0 + 0.5f, y1 = y0 + 0.5f;
            o.polygon({{x0, y0, h(x0, y0)}, {x1, y0, h(x1, y0)}, {x1, y1, h(x1, y1)}});
            o.polygon({{x0, y0, h(x0, y0)}, {x1, y1, h(x1, y1)}, {x0, y1, h(x0, y1)}});
        }
    return o;
}

UpAxisChoice guess(const fs::path& file) {
    return guess_obj_up_axis(load_obj(file), obj_header_comments(file));
}

}  // namespace

TEST_CASE("up axis: a y-up figure with spread arms falls through every cue to +y") {
    const UpAxisChoice c = guess(y_up_figure().write("figure.obj"));
    CHECK(c.axis == UpAxis::y);
    CHECK(c.reason.find("usual OBJ convention") != std::string::npos);
}

TEST_CASE("up axis: a z-up house is told by its floor slab") {
    const UpAxisChoice c = guess(z_up_house().write("house.obj"));
    CHECK(c.axis == UpAxis::z);
    CHECK(c.reason.find("ground or floor") != std::string::npos);
    // The same house turned y-up keeps its floor at the bottom, now of y.
    ObjText turned = z_up_house();
    turned.map([](Vec3 p) { return Vec3(p.x, p.z, -p.y); });
    CHECK(guess(turned.write("house_y.obj")).axis == UpAxis::y);
}

TEST_CASE("up axis: a model standing on the plane z = 0 is z-up") {
    const UpAxisChoice c = guess(z_up_figure(0.0f).write("figure_z0.obj"));
    CHECK(c.axis == UpAxis::z);
    CHECK(c.reason.find("z = 0") != std::string::npos);
}

TEST_CASE("up axis: flat terrain lies across its thin axis") {
    const UpAxisChoice c = guess(z_up_terrain().write("terrain.obj"));
    CHECK(c.axis == UpAxis::z);
    CHECK(c.reason.find("flat across z") != std::string::npos);
}

TEST_CASE("up axis: the exporter named in the header decides before the geometry") {
    // A z-up figure off the zero plane looks like nothing in particular: +y...
    CHECK(guess(z_up_figure(3.0f).write("figure_z3.obj")).axis == UpAxis::y);
    // ...unless the file says Rhino wrote it.
    const UpAxisChoice rhino = guess(z_up_figure(3.0f).write("rhino.obj", "# Rhino\n\n# 1 object\n"));
    CHECK(rhino.axis == UpAxis::z);
    CHECK(rhino.reason.find("rhino") != std::string::npos);
    // Blender exports +y up: its flat terrain stays +y whatever its shape.
    const fs::path blender = z_up_terrain().write("blender.obj", "# Blender 4.1.1\n# www.blender.org\n");
    CHECK(guess(blender).axis == UpAxis::y);
    // Only the leading comments count, not a comment after the first statement.
    ObjText late = z_up_figure(3.0f);
    const fs::path file = late.write("late.obj", "v 0 0 0\n# Rhino\n");
    CHECK(obj_header_comments(file).empty());
}

TEST_CASE("up axis: --up values are the six signed axes") {
    CHECK(parse_up_axis("y") == UpAxis::y);
    CHECK(parse_up_axis("+z") == UpAxis::z);
    CHECK(parse_up_axis("-x") == UpAxis::neg_x);
    CHECK(parse_up_axis("Z") == UpAxis::z);
    CHECK_FALSE(parse_up_axis("w").has_value());
    CHECK_FALSE(parse_up_axis("").has_value());
    CHECK_FALSE(parse_up_axis("-").has_value());
    CHECK_FALSE(parse_up_axis("yz").has_value());
    for (int a = 0; a < 6; ++a) CHECK(parse_up_axis(up_axis_name(UpAxis(a))) == UpAxis(a));
}

TEST_CASE("up axis: an explicit axis overrides the rule in the view scene") {
    const fs::path file = z_up_house().write("house_override.obj");
    ViewOptions options;
    SceneDesc guessed = make_view_scene(load_obj(file), false, options, file.string());
    CHECK(guessed.camera.up.z == doctest::Approx(1.0));
    options.up = UpAxis::neg_x;
    SceneDesc forced = make_view_scene(load_obj(file), false, options, file.string());
    CHECK(forced.camera.up.x == doctest::Approx(-1.0));
    REQUIRE(forced.planes.size() == 1);
    CHECK(forced.planes[0].normal.x == doctest::Approx(-1.0));
    CHECK(forced.planes[0].point.x == doctest::Approx(6.0));  // the ground touches the model's +x side
    CHECK(forced.background.up.x == doctest::Approx(-1.0));
}
