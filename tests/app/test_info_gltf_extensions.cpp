// `sahara info` on glTF files with EXT_mesh_gpu_instancing (instances counted,
// triangles stored once) and KHR_materials_variants (named; the default or the
// --variant chosen rendered, by `info` and `view`).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "app/cmd_info.h"
#include "cli_test_util.h"
#include "io/gltf_test_doc.h"
#include "io/image_io.h"
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

namespace {

/// A quad (so the view's centre pixel lands inside it) in material "plain",
/// which variant "Racing red" maps to "red".
void write_variants_gltf(const std::filesystem::path& file) {
    gltf::Doc d;
    const int pos = d.positions({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0});
    const int idx = d.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR", 6);
    d.node({{"mesh", d.mesh(pos, idx)}});
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
    d.write(file);
}

/// Linear RGB of the centre pixel of an image.
std::vector<float> centre_pixel(const std::string& file) {
    const auto img = read_image(file, false);
    const size_t at = 4 * (size_t(img->height / 2) * size_t(img->width) + size_t(img->width / 2));
    return {img->rgba[at], img->rgba[at + 1], img->rgba[at + 2]};
}

}  // namespace

TEST_CASE("info: a glTF with KHR_materials_variants names them and renders the default materials") {
    TempDir dir("info_variants");
    write_variants_gltf(dir.path / "variants.gltf");

    const LoadedModel m = load_model(dir.path / "variants.gltf");
    CHECK(m.variants == std::vector<std::string>{"Classic", "Racing red"});
    REQUIRE(m.meshes.size() == 1);
    const MaterialDesc& used = m.materials[m.meshes[0].material];
    CHECK(used.name == "plain");
    CHECK(used.albedo.color.y == doctest::Approx(0.4f));

    const json j = scene_info(dir / "variants.gltf").to_json();
    REQUIRE(j.contains("Material variants"));
    CHECK(j["Material variants"]["KHR_materials_variants"] == json({"Classic", "Racing red"}));
    CHECK(j["Material variants"]["Rendered"].is_null());
    const CliRun r = run_sahara("info variants.gltf", dir);
    CHECK(r.code == 0);
    CHECK(r.out.find("Classic, Racing red") != std::string::npos);
    CHECK(r.out.find("the default materials") != std::string::npos);
}

TEST_CASE("info and view --variant: the chosen variant is described and rendered") {
    TempDir dir("view_variants");
    write_variants_gltf(dir.path / "variants.gltf");
    const json j = scene_info(dir / "variants.gltf", "Racing red").to_json();
    CHECK(j["Material variants"]["Rendered"] == "Racing red");
    CliRun r = run_sahara("info variants.gltf --variant \"Racing red\"", dir);
    CHECK(r.code == 0);
    CHECK(r.out.find("Racing red") != std::string::npos);

    // The centre pixel is the quad: blue-grey by default, red in the variant.
    r = run_sahara("view variants.gltf --size 16 --spp 4 -q -o plain.pfm", dir);
    REQUIRE(r.code == 0);
    r = run_sahara("view variants.gltf --size 16 --spp 4 -q -o red.pfm --variant \"Racing red\"", dir);
    REQUIRE(r.code == 0);
    const std::vector<float> plain = centre_pixel(dir / "plain.pfm"), red = centre_pixel(dir / "red.pfm");
    CHECK(plain[2] > plain[0]);
    CHECK(red[0] > 2 * red[2]);

    r = run_sahara("view variants.gltf --size 16 --spp 1 -o green.png --variant Green", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("variants.gltf: KHR_materials_variants: no material variant named 'Green'; the file "
                     "has: Classic, Racing red") != std::string::npos);
    r = run_sahara("info variants.gltf --variant Green", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("no material variant named 'Green'") != std::string::npos);
}
