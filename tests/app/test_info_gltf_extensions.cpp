// `sahara info` on glTF files with EXT_mesh_gpu_instancing (instances counted,
// triangles stored once) and KHR_materials_variants (named, default rendered).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "app/cmd_info.h"
#include "cli_test_util.h"
#include "io/gltf_test_doc.h"
#include "io/model_loader.h"

using namespace sahara;
using namespace sahara::test;
using nlohmann::json;

TEST_CASE("info: a glTF with EXT_mesh_gpu_instancing counts its instances") {
    TempDir dir("info_gpu_instancing");
    gltf::Doc d;
    const int mesh = d.mesh(d.positions(gltf::kTriangle));
    const int t = d.accessor(std::vector<float>{0, 0, 0, 2, 0, 0, 4, 0, 0}, 5126, "VEC3", 3);
    d.node({{"mesh", mesh},
            {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", t}}}}}}}});
    d.write(dir.path / "three.gltf");
    const json j = scene_info(dir / "three.gltf").to_json();
    CHECK(j["Instances"]["Instances"] == 3);
    CHECK(j["Instances"]["Triangles stored"] == 1);
    CHECK(j["Instances"]["Triangles drawn"] == 3);
    CHECK(j["Bounds"]["Max"][0].get<double>() == doctest::Approx(5));
}

TEST_CASE("info: a glTF with KHR_materials_variants names them and renders the default materials") {
    TempDir dir("info_variants");
    gltf::Doc d;
    d.node({{"mesh", d.mesh(d.positions(gltf::kTriangle))}});
    d.j["materials"] = {
        {{"name", "plain"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.4, 0.6, 1}}}}},
        {{"name", "red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}}};
    json& prim = d.j["meshes"][0]["primitives"][0];
    prim["material"] = 0;
    prim["extensions"]["KHR_materials_variants"] = {{"mappings", {{{"material", 1}, {"variants", {1}}}}}};
    d.j["extensions"]["KHR_materials_variants"] = {
        {"variants", {{{"name", "Classic"}}, {{"name", "Racing red"}}}}};
    d.j["extensionsUsed"] = {"KHR_materials_variants"};
    d.j["extensionsRequired"] = {"KHR_materials_variants"};
    d.write(dir.path / "variants.gltf");

    const LoadedModel m = load_model(dir.path / "variants.gltf");
    CHECK(m.variants == std::vector<std::string>{"Classic", "Racing red"});
    REQUIRE(m.meshes.size() == 1);
    const MaterialDesc& used = m.materials[m.meshes[0].material];
    CHECK(used.name == "plain");
    CHECK(used.albedo.color.y == doctest::Approx(0.4f));

    const json j = scene_info(dir / "variants.gltf").to_json();
    REQUIRE(j.contains("Material variants"));
    CHECK(j["Material variants"]["KHR_materials_variants"] == json({"Classic", "Racing red"}));
    const CliRun r = run_sahara("info variants.gltf", dir);
    CHECK(r.code == 0);
    CHECK(r.out.find("Classic, Racing red (the default materials are rendered)") != std::string::npos);
}
