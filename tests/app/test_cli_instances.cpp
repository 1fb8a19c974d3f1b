// Instances through the command line: a glTF whose nodes share a mesh, and the
// scene format's `instance` object with a name that does not exist.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "app/cmd_info.h"
#include "cli_test_util.h"
#include "io/gltf_test_doc.h"
#include "io/model_loader.h"
#include "io/scene_parser.h"

using namespace sahara;
using namespace sahara::test;
using nlohmann::json;

TEST_CASE("instances: a glTF whose two nodes share one mesh loads as one mesh and two instances") {
    gltf::Doc d;
    const int mesh = d.mesh(d.positions(gltf::kTriangle));
    d.node({{"mesh", mesh}, {"translation", {-2, 0, 0}}});
    d.node({{"mesh", mesh}, {"translation", {2, 0, 0}}, {"scale", {1, 3, 1}}});
    TempDir dir("cli_instances_gltf");
    d.write(dir.path / "pair.gltf");
    gltf::write_text(dir.path / "scene.json",
                     R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "up": [0, 1, 0]},
                         "objects": [{"type": "mesh", "file": "pair.gltf"}]})");

    const SceneDesc desc = parse_scene_file(dir.path / "scene.json");
    CHECK(desc.meshes.size() == 1);
    REQUIRE(desc.prototypes.size() == 1);
    CHECK(desc.instances.size() == 2);
    // A plain model load (sahara view, the BVH tools) still copies per node.
    CHECK(load_model(dir.path / "pair.gltf").meshes.size() == 2);

    const json j = scene_info(dir / "scene.json").to_json();
    CHECK(j["Instances"]["Prototypes"] == 1);
    CHECK(j["Instances"]["Instances"] == 2);
    CHECK(j["Instances"]["Triangles stored"] == 1);
    CHECK(j["Instances"]["Triangles drawn"] == 2);
    CHECK(j["Bounds"]["Max"][0].get<double>() == doctest::Approx(3));
    CHECK(j["Bounds"]["Max"][1].get<double>() == doctest::Approx(3));
}

TEST_CASE("instances: an instance of an unknown name exits 2 naming it") {
    TempDir dir("cli_instances_bad_of");
    gltf::write_text(dir.path / "scene.json",
                     R"({"camera": {"position": [0, -5, 1], "look_at": [0, 0, 1]},
                   "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "name": "ball"},
                               {"type": "instance", "of": "bal"}]})");
    const CliRun r = run_sahara("render scene.json -o out.png", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("\"bal\"") != std::string::npos);
    CHECK(r.err.find("objects[1].of") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir.path / "out.png"));
}

TEST_CASE("instances: sahara bvh and bench report the instance level beside the scene's own tree") {
    TempDir dir("cli_instances_bvh");
    gltf::write_text(dir.path / "square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    gltf::write_text(dir.path / "scene.json",
                     R"({"camera": {"position": [0, -5, 1], "look_at": [0, 0, 0]},
                   "objects": [{"type": "mesh", "file": "square.obj", "name": "a"},
                               {"type": "instance", "of": "a", "name": "b", "transform": {"translate": [2, 0, 0]}},
                               {"type": "instance", "of": "b", "transform": {"translate": [0, 2, 0]}},
                               {"type": "sphere", "center": [0, 0, 3], "radius": 1}]})");
    const CliRun bvh = run_sahara("bvh scene.json --size 16 --json", dir);
    REQUIRE(bvh.code == 0);
    const json j = json::parse(bvh.out);
    CHECK(j["primitives"] == 1);  // the sphere: the scene's own tree
    REQUIRE(j.contains("instances"));
    CHECK(j["instances"]["instances"] == 3);
    CHECK(j["instances"]["prototypes"] == 1);
    CHECK(j["instances"]["triangles_stored"] == 2);
    CHECK(j["instances"]["triangles_drawn"] == 6);
    CHECK(j["instances"]["top_level_leaves"].get<int>() >= 2);  // leaves hold one or two instances
    const CliRun text = run_sahara("bvh scene.json --size 16", dir);
    CHECK(text.out.find("3 of 1 prototypes") != std::string::npos);
    const CliRun bench = run_sahara("bench scene.json --size 16 --json --no-embree", dir);
    REQUIRE(bench.code == 0);
    CHECK(json::parse(bench.out)["instances"]["instances"] == 3);
}
