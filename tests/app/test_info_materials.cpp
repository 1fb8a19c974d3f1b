// `sahara info` lists each material by what it uses and names what the renderer ignores.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "app/cmd_info.h"
#include "cli_test_util.h"
#include "io/gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

bool contains(const json& list, const std::string& item) {
    for (const json& v : list)
        if (v == item) return true;
    return false;
}

/// A one-triangle glTF with uvs, RGBA vertex colours (alpha 0.5) and material
/// `material`, whose textures 0..3 all show tiny.png.
fs::path write_gltf(const fs::path& dir, const json& material) {
    gltf::Doc d = gltf::textured_doc(material);
    const int colors =
        d.accessor(std::vector<float>{1, 0, 0, 0.5f, 0, 1, 0, 0.5f, 0, 0, 1, 0.5f}, 5126, "VEC4", 3);
    d.j["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = colors;
    gltf::tiny_png(dir);  // writes dir/tiny.png
    d.j["images"] = {{{"uri", "tiny.png"}}};
    d.j["textures"] = {{{"source", 0}}, {{"source", 0}}, {{"source", 0}}, {{"source", 0}}};
    return d.write(dir / "m.gltf");
}

}  // namespace

TEST_CASE("info: a glTF pbr material with its textures and vertex colours and the inputs it ignores") {
    const fs::path dir = gltf::scratch("info_pbr");
    const json material = {
        {"name", "paint"},
        {"pbrMetallicRoughness",
         {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 1}}}}},
        {"normalTexture", {{"index", 2}}},
        {"occlusionTexture", {{"index", 3}}},
        {"emissiveFactor", {1, 1, 1}},
        {"emissiveTexture", {{"index", 3}}},
        {"alphaMode", "BLEND"},
        {"extensions",
         {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1}}},
          {"KHR_materials_dispersion", {{"dispersion", 0.5}}},
          {"KHR_materials_diffuse_transmission", {{"diffuseTransmissionFactor", 0.25}}},
          {"KHR_materials_volume_scatter", json::object()},
          {"KHR_materials_iridescence", {{"iridescenceFactor", 1}}},
          {"KHR_materials_transmission", {{"transmissionFactor", 0.5}}},
          {"KHR_materials_volume",
           {{"thicknessFactor", 1}, {"attenuationDistance", 2}, {"attenuationColor", {1, 0.5, 0.5}}}}}}};
    const std::string file = write_gltf(dir, material).string();
    const json j = scene_info(file).to_json();
    CHECK(j["Materials"]["pbr"] == 1);
    const json& m = j["Materials"]["[0] paint"];
    CHECK(m["type"] == "pbr");
    for (const char* role : {"base colour", "metallic-roughness", "normal map", "emission"})
        CHECK_MESSAGE(m["textures"].contains(role), std::string(role));
    CHECK_FALSE(m["textures"].contains("alpha"));  // glTF's alpha comes with the base colour
    CHECK(m["vertex_colors"] == true);
    CHECK(m["vertex_alpha"] == true);  // BLEND: COLOR_0's alpha 0.5 is used
    CHECK(m["emission"] == true);
    CHECK(m["transmission"].get<double>() == doctest::Approx(0.5));
    CHECK(m["alpha_mode"] == "blend");
    CHECK(m["double_sided"] == false);
    const json& ignored = j["Ignored inputs"]["[0] paint"];
    for (const char* what : {"occlusion map", "KHR_materials_volume_scatter"})
        CHECK_MESSAGE(contains(ignored, what), std::string(what));
    CHECK_FALSE(contains(ignored, "KHR_materials_dispersion"));            // rendered
    CHECK_FALSE(contains(ignored, "KHR_materials_diffuse_transmission"));  // rendered
    CHECK(m["dispersion"].get<double>() == doctest::Approx(0.5));
    CHECK(m["diffuse_transmission"].get<double>() == doctest::Approx(0.25));
    CHECK(contains(m["extensions"], "KHR_materials_dispersion"));
    CHECK(contains(m["extensions"], "KHR_materials_diffuse_transmission"));
    CHECK_FALSE(contains(ignored, "KHR_materials_clearcoat"));    // rendered
    CHECK_FALSE(contains(ignored, "KHR_materials_iridescence"));  // rendered
    CHECK(m["clearcoat"] == 1.0);
    CHECK_FALSE(contains(ignored, "volume attenuation (not rendered yet)"));  // rendered now
    CHECK(m["volume_attenuation"] == true);
    CHECK_FALSE(contains(ignored, "vertex-colour alpha"));  // used now

    // The text form says the same.
    TempDir run("info_pbr_text");
    const CliRun r = run_sahara("info " + file, run);
    CHECK(r.code == 0);
    for (const char* text :
         {"[0] paint", "textures: base colour, metallic-roughness, normal map, emission",
          "vertex colours and alpha", "transmission 0.5, ior 1.5", "alpha blend", "one-sided",
          "clearcoat 1 (roughness 0)", "dispersion 0.5", "diffuse transmission 0.25", "Ignored inputs",
          "occlusion map, KHR_materials_volume_scatter"})
        CHECK_MESSAGE(r.out.find(text) != std::string::npos, std::string(text));
}

TEST_CASE("info: an opaque glTF material has no alpha and ignores no vertex-colour alpha") {
    const fs::path dir = gltf::scratch("info_opaque");
    const json j = scene_info(write_gltf(dir, {{"doubleSided", true}}).string()).to_json();
    const json& m = j["Materials"]["[0] materials[0]"];
    CHECK(m["alpha_mode"] == "opaque");
    CHECK(m["double_sided"] == true);
    CHECK(m["textures"].empty());
    CHECK(m["vertex_colors"] == true);
    CHECK(m["vertex_alpha"] == false);
    CHECK_FALSE(j.contains("Ignored inputs"));  // OPAQUE: glTF itself ignores alpha
}

TEST_CASE("info: glTF material extensions are named with the materials that use them") {
    const fs::path dir = gltf::scratch("info_extensions");
    const json unlit = {{"extensions", {{"KHR_materials_unlit", json::object()}}}};
    json j = scene_info(write_gltf(dir, unlit).string()).to_json();
    CHECK(j["Materials"]["unlit"] == 1);
    const json& u = j["Materials"]["[0] materials[0]"];
    CHECK(u["type"] == "unlit");
    CHECK(u["extensions"] == json::array({"KHR_materials_unlit"}));
    CHECK_FALSE(j.contains("Ignored inputs"));

    const json specular = {
        {"extensions", {{"KHR_materials_specular", {{"specularColorTexture", {{"index", 1}}}}}}}};
    j = scene_info(write_gltf(dir, specular).string()).to_json();
    const json& s = j["Materials"]["[0] materials[0]"];
    CHECK(s["type"] == "pbr");
    CHECK(s["textures"].contains("specular colour"));
    CHECK(s["extensions"] == json::array({"KHR_materials_specular"}));

    TempDir run("info_extensions_text");
    const CliRun r = run_sahara("info " + (dir / "m.gltf").string(), run);
    CHECK(r.code == 0);
    CHECK(r.out.find("extensions: KHR_materials_specular") != std::string::npos);
}

TEST_CASE("info: OBJ and MTL materials by what they use") {
    TempDir dir("info_obj");
    gltf::tiny_png(dir.path);
    gltf::write_text(dir.path / "m.mtl",
                     "newmtl plain\nKd 0.5 0.5 0.5\n"
                     "newmtl lamp\nKd 0 0 0\nKe 4 4 4\n"
                     "newmtl decal\nmap_Kd tiny.png\nnorm tiny.png\nd 0.5\nmap_Ks spec.png\nPs 0.5\n");
    gltf::write_text(
        dir.path / "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "usemtl plain\nf 1/1 2/2 3/3\nusemtl lamp\nf 1/1 3/3 2/2\nusemtl decal\nf 1/1 2/2 3/3\n");
    const json j = scene_info(dir / "m.obj").to_json();
    json plain, lamp, decal;
    for (const auto& [label, v] : j["Materials"].items()) {
        if (!v.is_object()) continue;
        if (v["name"] == "plain") plain = v;
        if (v["name"] == "lamp") lamp = v;
        if (v["name"] == "decal") decal = v;
    }
    CHECK(plain["type"] == "lambertian");
    CHECK(plain["textures"].empty());
    CHECK(plain["emission"] == false);
    CHECK(lamp["type"] == "emissive");
    CHECK(lamp["emission"] == true);
    CHECK(decal["type"] == "pbr");
    CHECK(decal["textures"].contains("base colour"));
    CHECK(decal["textures"].contains("normal map"));
    CHECK(decal["alpha_mode"] == "blend");
    CHECK(decal["vertex_colors"] == false);
    REQUIRE(j.contains("Ignored inputs"));
    CHECK(j["Ignored inputs"].size() == 1);  // only decal
    for (const auto& [label, ignored] : j["Ignored inputs"].items()) {
        CHECK(label.find("decal") != std::string::npos);
        CHECK(contains(ignored, "map_Ks"));
        CHECK(contains(ignored, "Ps (sheen)"));
    }
}

TEST_CASE("info: an OBJ with vertex colours says its lambertian material uses them") {
    TempDir dir("info_obj_colours");
    gltf::write_text(dir.path / "m.mtl", "newmtl plain\nKd 0.5 0.5 0.5\n");
    gltf::write_text(dir.path / "m.obj",
                     "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nusemtl plain\nf 1 2 3\n");
    const json j = scene_info(dir / "m.obj").to_json();
    json m;
    for (const auto& [label, v] : j["Materials"].items())
        if (v.is_object() && v["name"] == "plain") m = v;
    CHECK(m["type"] == "lambertian");
    CHECK(m["vertex_colors"] == true);
    TempDir run("info_obj_colours_text");
    const CliRun r = run_sahara("info " + (dir.path / "m.obj").string(), run);
    CHECK(r.code == 0);
    CHECK(r.out.find("lambertian; vertex colours") != std::string::npos);

    // A scene material given to the coloured mesh is tinted too, and says so.
    gltf::write_text(
        dir.path / "s.json",
        R"({"format": "scene/1", "camera": {"position": [0, -3, 1], "look_at": [0, 0, 0]}, "materials": {"red": {"type": "metal", "albedo": [1, 0, 0]}},
                         "objects": [{"type": "mesh", "file": "m.obj", "material": "red"}]})");
    const json scene = scene_info(dir / "s.json").to_json();
    json red;
    for (const auto& [label, v] : scene["Materials"].items())
        if (v.is_object() && v["name"] == "red") red = v;
    CHECK(red["type"] == "metal");
    CHECK(red["vertex_colors"] == true);
}

TEST_CASE("info: a glTF anisotropic material lists the extension and its direction texture") {
    const fs::path dir = gltf::scratch("info_anisotropy");
    const json material = {{"name", "brushed"},
                           {"extensions",
                            {{"KHR_materials_anisotropy",
                              {{"anisotropyStrength", 0.5},
                               {"anisotropyRotation", 1},
                               {"anisotropyTexture", {{"index", 1}}}}}}}};
    const std::string file = write_gltf(dir, material).string();
    const json j = scene_info(file).to_json();
    const json& m = j["Materials"]["[0] brushed"];
    CHECK(m["textures"].contains("anisotropy"));
    CHECK(m["anisotropy"].get<double>() == doctest::Approx(0.5));
    CHECK(contains(m["extensions"], "KHR_materials_anisotropy"));
    CHECK_FALSE(j.contains("Ignored inputs"));
    TempDir run("info_anisotropy_text");
    const CliRun r = run_sahara("info " + file, run);
    CHECK(r.code == 0);
    for (const char* text :
         {"textures: anisotropy", "anisotropy 0.5 (rotation 1)", "extensions: KHR_materials_anisotropy"})
        CHECK_MESSAGE(r.out.find(text) != std::string::npos, std::string(text));
}
