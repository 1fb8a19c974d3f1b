// KHR_materials_dispersion and KHR_materials_diffuse_transmission as they reach
// MaterialDesc, and the messages bad values get.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "gltf_test_doc.h"
#include "io/scene_parser.h"

using namespace sahara;
using namespace sahara::test;
using namespace sahara::test::gltf;

namespace {

/// A one-triangle file whose material has `extensions`, with one 1x1 image of
/// the texel (255, 128, 40, 64).
fs::path material_file(const fs::path& dir, const json& extensions) {
    json material = {{"pbrMetallicRoughness", {{"metallicFactor", 0}}}};
    if (!extensions.is_null()) material["extensions"] = extensions;
    Doc d = textured_doc(material);
    const uint8_t texel[4] = {255, 128, 40, 64};
    write_image_u8(dir / "t.png", 1, 1, 4, texel);
    d.j["images"] = {{{"uri", "t.png"}}};
    d.j["textures"] = {{{"source", 0}}};
    return d.write(dir / "m.gltf");
}

bool has(const std::vector<std::string>& list, const std::string& item) {
    return std::find(list.begin(), list.end(), item) != list.end();
}

const json kGlass = {{"KHR_materials_transmission", {{"transmissionFactor", 1}}},
                     {"KHR_materials_volume", {{"thicknessFactor", 1}}},
                     {"KHR_materials_dispersion", {{"dispersion", 0.8}}}};

const json kColorTexture = {
    {"index", 0}, {"texCoord", 1}, {"extensions", {{"KHR_texture_transform", {{"scale", {2, 2}}}}}}};

const json kTranslucent = {{"KHR_materials_diffuse_transmission",
                            {{"diffuseTransmissionFactor", 0.5},
                             {"diffuseTransmissionTexture", {{"index", 0}}},
                             {"diffuseTransmissionColorFactor", {1.0, 0.5, 0.25}},
                             {"diffuseTransmissionColorTexture", kColorTexture}}}};

}  // namespace

TEST_CASE("glTF dispersion: the value reaches the material") {
    const fs::path dir = scratch("gltf_dispersion");
    const MaterialDesc m = load_gltf(material_file(dir, kGlass)).materials.at(0);
    CHECK(m.dispersion == doctest::Approx(0.8f));
    CHECK_FALSE(m.thin_walled);
    CHECK(has(m.extensions, "KHR_materials_dispersion"));
    CHECK(m.ignored.empty());
    // The extension's default: none.
    json bare = kGlass;
    bare["KHR_materials_dispersion"] = json::object();
    CHECK(load_gltf(material_file(dir, bare)).materials.at(0).dispersion == 0.0f);
}

TEST_CASE("glTF dispersion: bad values are refused naming the file and element") {
    const fs::path dir = scratch("gltf_dispersion_bad");
    for (const json& value : {json(-0.5), json("lots"), json::array({1})}) {
        json ext = kGlass;
        ext["KHR_materials_dispersion"]["dispersion"] = value;
        const std::string e = error_of([&] { load_gltf(material_file(dir, ext)); });
        INFO(e);
        CHECK(e.find("m.gltf") != std::string::npos);
        CHECK(e.find("materials[0].extensions.KHR_materials_dispersion.dispersion: must be a number >= 0") !=
              std::string::npos);
    }
}

TEST_CASE(
    "glTF diffuse transmission: factors and textures with their uv sets and transforms reach the material") {
    const fs::path dir = scratch("gltf_diffuse_transmission");
    const LoadedModel model = load_gltf(material_file(dir, kTranslucent));
    const MaterialDesc& m = model.materials.at(0);
    CHECK(m.diffuse_transmission == 0.5f);
    CHECK(m.diffuse_transmission_color == Rgb(1.0f, 0.5f, 0.25f));
    REQUIRE(m.diffuse_transmission_texture >= 0);
    REQUIRE(m.diffuse_transmission_color_texture >= 0);
    const TextureDesc& share = model.textures.at(size_t(m.diffuse_transmission_texture));
    const TextureDesc& color = model.textures.at(size_t(m.diffuse_transmission_color_texture));
    CHECK(share.image->rgba.at(3) == doctest::Approx(64 / 255.0f));  // the share is in A
    // The share is data (read linear), the colour sRGB-decoded: darker from the same texel.
    CHECK(color.image->rgba.at(1) < share.image->rgba.at(1) - 0.01f);
    CHECK(share.texcoord == 0);
    CHECK(color.texcoord == 1);
    CHECK(color.uv_scale.x == 2.0f);
    CHECK(has(m.extensions, "KHR_materials_diffuse_transmission"));
    std::vector<std::string> roles;
    for_each_texture_slot(m, [&](const char* role, int index) {
        if (index >= 0) roles.push_back(role);
    });
    CHECK(has(roles, "diffuse transmission"));
    CHECK(has(roles, "diffuse transmission colour"));
    // The defaults: none, white.
    const MaterialDesc bare =
        load_gltf(material_file(dir, {{"KHR_materials_diffuse_transmission", json::object()}}))
            .materials.at(0);
    CHECK(bare.diffuse_transmission == 0.0f);
    CHECK(bare.diffuse_transmission_color == Rgb(1.0f));
}

TEST_CASE("glTF diffuse transmission: bad values are refused naming the file and element") {
    const fs::path dir = scratch("gltf_diffuse_transmission_bad");
    const std::string prefix = "materials[0].extensions.KHR_materials_diffuse_transmission.";
    for (const auto& [key, value, message] :
         {std::tuple<const char*, json, const char*>{"diffuseTransmissionFactor", 1.5,
                                                     "must be a number in [0, 1]"},
          {"diffuseTransmissionFactor", "half", "must be a number in [0, 1]"},
          {"diffuseTransmissionColorFactor", json::array({1, 0.5}), "must be 3 numbers in [0, 1]"},
          {"diffuseTransmissionColorFactor", json::array({1, -0.5, 0}), "must be 3 numbers in [0, 1]"},
          {"diffuseTransmissionTexture", json{{"index", 9}}, "texture 9 does not exist"}}) {
        json ext = kTranslucent;
        ext["KHR_materials_diffuse_transmission"][key] = value;
        const std::string e = error_of([&] { load_gltf(material_file(dir, ext)); });
        INFO(key << ": " << e);
        CHECK(e.find("m.gltf") != std::string::npos);
        CHECK(e.find(prefix + key) != std::string::npos);
        CHECK(e.find(message) != std::string::npos);
    }
}
