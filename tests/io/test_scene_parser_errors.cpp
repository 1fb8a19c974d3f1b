#include <doctest/doctest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include "scene_parser_test_util.h"

using namespace sahara;
using namespace sahara::parser_test;

TEST_CASE("scene parser: bad input names file, JSON path and expectation") {
    struct Case {
        std::string json;
        std::vector<std::string> fragments;
    };
    const std::string cam = R"("camera": {"position": [0, 0, 0], "look_at": [0, 1, 0]})";
    const std::vector<Case> cases = {
        {with_objects(R"([{"type": "sphere", "radius": 1}, {"type": "sphere", "radius": -1}])"),
         {"objects[1].radius: expected a number > 0, got -1"}},
        {with_objects(R"([{"type": "sphere", "raduis": 1}])"),
         {"objects[0].raduis: unknown key", "allowed here: type, center, radius"}},
        {"{" + cam + R"(, "objects": [], "colour": 1})", {"colour: unknown key"}},
        {"{" + cam + R"(, "objects": [], "render": {"width": "640"}})",
         {"render.width: expected an integer in [1, 32768], got \"640\""}},
        {"{" + cam + R"(, "objects": [], "render": {"width": 0}})",
         {"render.width: expected an integer in [1, 32768], got 0"}},
        {"{" + cam + R"(, "objects": [], "render": {"height": 40000}})",
         {"render.height: expected an integer in [1, 32768]"}},
        {"{" + cam + R"(, "objects": [], "render": {"width": 640.5}})",
         {"render.width: expected an integer"}},
        {"{" + cam + R"(, "objects": [], "render": {"spp": 0}})",
         {"render.spp: expected an integer >= 1, got 0"}},
        {"{" + cam + R"(, "objects": [], "render": {"max_depth": 0}})",
         {"render.max_depth: expected an integer in [1, 1024]"}},
        {"{" + cam + R"(, "objects": [], "render": {"seed": -1}})",
         {"render.seed: expected an integer in [0,"}},
        {"{" + cam + R"(, "objects": [], "render": {"integrator": "raytrace"}})",
         {"render.integrator: expected one of \"path\", \"whitted\"", "got \"raytrace\""}},
        {"{" + cam + R"(, "objects": [], "render": {"tonemap": "agx"}})",
         {"render.tonemap: expected one of \"clamp\""}},
        {"{" + cam + R"(, "objects": [], "render": {"bvh_builder": "lbvh"}})",
         {"render.bvh_builder: expected one of \"binned\""}},
        {"{" + cam + R"(, "objects": [], "render": {"time_limit_s": 0}})",
         {"render.time_limit_s: expected a number > 0"}},
        {"{" + cam + R"(, "objects": [], "render": {"exposure": 100}})",
         {"render.exposure: expected a number in [-64, 64]"}},
        {"{" + cam + R"(, "objects": [], "format": "scene/2"})", {"format: expected one of \"scene/1\""}},
        {with_objects(R"([{"type": "sphere", "radius": 1e999}])"),
         {"line 1", "column", "number overflow", "1e999"}},
        {with_objects(R"([{"type": "sphere", "radius": 1e39}])"),
         {"objects[0].radius: expected a number > 0 that fits a 32-bit float, got 1e+39"}},
        {with_objects(R"([{"type": "sphere", "center": [0, 1]}])"),
         {"objects[0].center: expected [x, y, z]: 3 numbers, got [0,1]"}},
        {with_objects(R"([{"type": "sphere", "center": [0, 1, true]}])"),
         {"objects[0].center[2]: expected a number, got true"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "vfov": 180}, "objects": []})",
         {"camera.vfov: expected a number in (0, 180), got 180"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "vfov": 0}, "objects": []})",
         {"camera.vfov: expected a number in (0, 180)"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "euler": [0, 0, 0]}, "objects": []})",
         {"camera: mixes the look-at form (\"look_at\") with the euler form (\"euler\")"}},
        {R"({"camera": {"position": [0, 0, 0], "up": [0, 1, 0], "focal_length": 1}, "objects": []})",
         {"camera: mixes the look-at form (\"up\")"}},
        {R"({"camera": {"position": [0, 0, 0]}, "objects": []})", {"camera: missing key \"look_at\""}},
        {R"({"camera": {"look_at": [0, 0, 0]}, "objects": []})", {"camera: missing key \"position\""}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, 0]}, "objects": []})",
         {"camera.look_at: look_at must differ from position"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "up": [0, 2, 0]}, "objects": []})",
         {"camera.up: up must not be parallel"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "objects": []})",
         {"camera.look_at: the viewing direction is parallel to the default up"}},
        {R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "shutter": [1, 0]}, "objects": []})",
         {"camera.shutter: expected [open, close] with open <= close"}},
        {R"({"camera": {"position": [0, 0, 0], "euler": [0, 0, 0], "focal_length": -1}, "objects": []})",
         {"camera.focal_length: expected a number > 0"}},
        {R"({"objects": []})", {"missing key \"camera\""}},
        {"{" + cam + "}", {"missing key \"objects\""}},
        {"{" + cam + R"(, "objects": {}})", {"objects: expected an array, got {}"}},
        {"[1, 2]", {"expected an object, got [1,2]"}},
        {with_objects(R"([{"type": "sphere", "material": "gold"}])", R"({"white": {"type": "lambertian"}})"),
         {"objects[0].material: unknown material \"gold\" (defined: \"default\", \"white\")"}},
        {with_objects("[]", R"({"white": {"type": "lambertian"}, "white": {"type": "metal"}})"),
         {"materials.white: duplicate key"}},
        {with_objects(R"([{"type": "sphere"}, {"type": "sphere", "radius": 1, "radius": 2}])"),
         {"objects[1].radius: duplicate key"}},
        {with_objects("[]", R"({"default": {"type": "lambertian"}})"),
         {"materials.default: the name \"default\" is reserved"}},
        {with_objects("[]", R"({"m": {"type": "metal", "alpha": 0.5}})"), {"materials.m.alpha: unknown key"}},
        {with_objects("[]", R"({"m": {"type": "plastic"}})"),
         {"materials.m.type: expected one of \"lambertian\", \"metal\"", "\"pbr\", \"unlit\""}},
        {with_objects("[]", R"({"m": {"type": "unlit", "albedo": [1, 0, 0]}})"),
         {"materials.m.albedo: unknown key", "allowed here: type, color, alpha, alpha_cutoff"}},
        {with_objects("[]", R"({"m": {"type": "unlit", "color": [1, 0, 0], "emission": [1, 1, 1]}})"),
         {"materials.m.emission: unknown key"}},
        {with_objects("[]", R"({"m": {"type": "unlit", "color": [0.5, 2, 0]}})"),
         {"materials.m.color[1]: expected a number in [0, 1], got 2"}},
        {with_objects("[]", R"({"m": {"type": "unlit", "color": "red"}})"),
         {"materials.m.color: expected [r, g, b]"}},
        {with_objects("[]", R"({"m": {"type": "unlit", "color": {"texture": "textures/nope.png"}}})"),
         {"materials.m.color.texture: file not found:", "textures/nope.png"}},
        {with_objects("[]", R"({"m": {"type": "unlit", "alpha_cutoff": -1}})"),
         {"materials.m.alpha_cutoff: expected a number in [0, 1], got -1"}},
        {with_objects("[]", R"({"m": {"albedo": [1, 1, 1]}})"), {"materials.m: missing key \"type\""}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "albedo": [0.5, 1.5, 0]}})"),
         {"materials.m.albedo[1]: expected a number in [0, 1], got 1.5"}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "albedo": {"marble": 1}}})"),
         {"materials.m.albedo.marble: unknown key"}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "albedo": "red"}})"),
         {"materials.m.albedo: expected [r, g, b]"}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "albedo": {"checker": {"scale": 0}}}})"),
         {"materials.m.albedo.checker.scale: expected a number > 0, got 0"}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "alpha": 2}})"),
         {"materials.m.alpha: expected a number in [0, 1], got 2"}},
        {with_objects("[]", R"({"m": {"type": "emissive", "radiance": [1, -1, 1]}})"),
         {"materials.m.radiance[1]: expected a number >= 0"}},
        {with_objects("[]", R"({"m": {"type": "metal", "roughness": 2}})"),
         {"materials.m.roughness: expected a number in [0, 1]"}},
        {with_objects("[]", R"({"m": {"type": "lambertian", "albedo": {"texture": "textures/nope.png"}}})"),
         {"materials.m.albedo.texture: file not found:", "textures/nope.png"}},
        {"{" + cam + R"(, "objects": [], "background": {"type": "envmap"}})",
         {"background: missing key \"file\""}},
        {"{" + cam + R"(, "objects": [], "background": {"type": "constant", "top": [1, 1, 1]}})",
         {"background.top: unknown key"}},
        {"{" + cam + R"(, "objects": [], "background": {"type": "gradient", "up": [0, 0, 0]}})",
         {"background.up: expected a non-zero vector"}},
        {with_objects(R"([{"type": "torus"}])"),
         {"objects[0].type: expected one of \"sphere\"", "got \"torus\""}},
        {with_objects(R"([{"radius": 1}])"), {"objects[0]: missing key \"type\""}},
        {with_objects(R"([{"type": "sphere", "transform": {"scale": [1, 2, 1]}}])"),
         {"objects[0].transform: a sphere only takes a uniform scale (use an ellipsoid"}},
        {with_objects(R"([{"type": "sphere", "transform": {"scale": 0}}])"),
         {"objects[0].transform.scale: expected a non-zero number"}},
        {with_objects(
             R"([{"type": "plane", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "translate": [1, 0, 0]}}])"),
         {"objects[0].transform: \"matrix\" excludes"}},
        {with_objects(
             R"([{"type": "plane", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]}}])"),
         {"objects[0].transform.matrix: expected an affine matrix"}},
        {with_objects(R"([{"type": "plane", "transform": {"matrix": [1, 0, 0]}}])"),
         {"objects[0].transform.matrix: expected an array of 16 elements"}},
        {with_objects(R"([{"type": "plane", "transform": {"skew": 1}}])"),
         {"objects[0].transform.skew: unknown key"}},
        {with_objects(R"([{"type": "plane", "normal": [0, 0, 0]}])"),
         {"objects[0].normal: expected a non-zero vector"}},
        {with_objects(R"([{"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]}])"),
         {"objects[0].max: expected max > min"}},
        {with_objects(R"([{"type": "mesh"}])"), {"objects[0]: missing key \"file\""}},
        {with_objects(R"([{"type": "mesh", "file": "meshes/none.obj"}])"),
         {"objects[0].file: file not found:", "meshes/none.obj"}},
        {with_objects(R"([{"type": "ellipsoid", "radii": [1, 0, 1]}])"),
         {"objects[0].radii[1]: expected a number > 0, got 0"}},
        {with_objects(R"([{"type": "ellipsoid", "axis": [1, 0, 0]}])"), {"objects[0].axis: unknown key"}},
        {with_objects(R"([{"type": "cylinder", "axis": [0, 0, 0]}])"),
         {"objects[0].axis: expected a non-zero vector"}},
        {with_objects(R"([{"type": "cylinder", "capped": 1}])"),
         {"objects[0].capped: expected true or false, got 1"}},
        {with_objects(R"([{"type": "cone", "angle": 90}])"),
         {"objects[0].angle: expected a number in (0, 90), got 90"}},
        {with_objects(R"([{"type": "paraboloid", "height": -2}])"),
         {"objects[0].height: expected a number > 0, got -2"}},
        {with_objects(R"([{"type": "hyperboloid", "radius": 1, "waist": 1}])"),
         {"objects[0].waist: expected waist < radius"}},
        {with_objects(R"([{"type": "quadric", "bounds": {"min": [0, 0, 0], "max": [1, 1, 1]}}])"),
         {"objects[0]: missing key \"coefficients\""}},
        {with_objects(
             R"([{"type": "quadric", "coefficients": [0, 0, 0, 0, 0, 0, 1, 0, 0, 0], "bounds": {"min": [0, 0, 0], "max": [1, 1, 1]}}])"),
         {"objects[0].coefficients: expected at least one of A..F"}},
        {with_objects(
             R"([{"type": "quadric", "coefficients": [1, 1, 1, 0, 0, 0, 0, 0, 0, -1], "bounds": {"min": [0, 0, 0], "max": [1, -1, 1]}}])"),
         {"objects[0].bounds.max: expected max > min"}},
        {"{" + cam + R"(, "objects": [], "lights": [{"type": "spot"}]})",
         {"lights[0].type: expected one of \"point\", \"directional\""}},
        {"{" + cam + R"(, "objects": [], "lights": [{"type": "point", "intensity": [1, 1, -1]}]})",
         {"lights[0].intensity[2]: expected a number >= 0"}},
        {"{" + cam + R"(, "objects": [], "lights": [{"type": "point", "direction": [1, 1, 1]}]})",
         {"lights[0].direction: unknown key"}},
        {"{" + cam + R"(, "objects": [], "lights": [{"type": "directional", "direction": [0, 0, 0]}]})",
         {"lights[0].direction: expected a non-zero"}},
    };
    for (const Case& c : cases) {
        CAPTURE(c.json);
        check_contains(error_of(c.json), c.fragments);
    }
}

TEST_CASE("scene parser: a missing file names the directory relative paths resolve against") {
    const fs::path scratch = fs::temp_directory_path() / ("sahara_parser_test_" + std::to_string(::getpid()));
    check_contains(error_of(with_objects(R"([{"type": "mesh", "file": "meshes/none.obj"}])")),
                   {"objects[0].file: file not found: ",
                    "meshes/none.obj (relative paths resolve against " + scratch.string() + ")"});
    const std::string absolute =
        error_of(with_objects(R"([{"type": "mesh", "file": "/nonexistent/none.obj"}])"));
    const std::string expected = "objects[0].file: file not found: /nonexistent/none.obj";
    REQUIRE(absolute.size() >= expected.size());
    CHECK(absolute.substr(absolute.size() - expected.size()) == expected);  // no hint about relative paths
}

TEST_CASE("scene parser: broken JSON reports line and column") {
    check_contains(error_of("{\n  \"camera\": {},\n  \"objects\" []\n}"),
                   {"line 3, column 13", "invalid JSON"});
    check_contains(error_of("{\n  \"objects\": [\n"), {"line 3", "invalid JSON", "unexpected end of input"});
    check_contains(error_of(""), {"line 1, column 1", "invalid JSON"});
    check_contains(error_of("{\"objects\": [] // comment\n}"), {"line 1, column 16", "invalid JSON"});
}
