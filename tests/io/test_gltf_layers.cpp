// KHR_materials_clearcoat and KHR_materials_sheen as they reach MaterialDesc.
#include <doctest/doctest.h>

#include "gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

/// A one-triangle file whose material has `extensions`, with 1x1 images:
/// 0 the texel (200, 100, 50), 1 a flat normal, 2 alpha 64 (kept apart: the
/// PNG codec stores colour with alpha premultiplied, which would bend the texel).
LoadedModel load_layers(const fs::path& dir, const json& extensions, const json& required = json::array()) {
    Doc d = textured_doc({{"extensions", extensions}});
    const uint8_t colour[4] = {200, 100, 50, 255}, flat[4] = {128, 128, 255, 255},
                  alpha[4] = {255, 255, 255, 64};
    write_image_u8(dir / "texel.png", 1, 1, 4, colour);
    write_image_u8(dir / "flat.png", 1, 1, 4, flat);
    write_image_u8(dir / "alpha.png", 1, 1, 4, alpha);
    d.j["images"] = {{{"uri", "texel.png"}}, {{"uri", "flat.png"}}, {{"uri", "alpha.png"}}};
    d.j["textures"] = {{{"source", 0}}, {{"source", 1}}, {{"source", 2}}};
    if (!required.empty()) d.j["extensionsRequired"] = required;
    return load_gltf(d.write(dir / "layers.gltf"));
}

float texel(const LoadedModel& m, int texture, int channel) {
    REQUIRE(texture >= 0);
    return m.textures.at(size_t(texture)).image->rgba.at(size_t(channel));
}

}  // namespace

TEST_CASE("glTF clearcoat: factors and textures reach the material and nothing is ignored") {
    const fs::path dir = scratch("layers_clearcoat");
    const json ext = {{"KHR_materials_clearcoat",
                       {{"clearcoatFactor", 0.8},
                        {"clearcoatTexture", {{"index", 0}}},
                        {"clearcoatRoughnessFactor", 0.3},
                        {"clearcoatRoughnessTexture", {{"index", 0}}},
                        {"clearcoatNormalTexture", {{"index", 1}, {"scale", 0.5}}}}}};
    const LoadedModel m = load_layers(dir, ext, {"KHR_materials_clearcoat"});
    const PbrLayersDesc& l = m.materials.at(0).layers;
    CHECK(l.clearcoat == doctest::Approx(0.8f));
    CHECK(l.clearcoat_roughness == doctest::Approx(0.3f));
    CHECK(texel(m, l.clearcoat_texture, 0) == doctest::Approx(200 / 255.0f));  // data: linear
    CHECK(texel(m, l.clearcoat_roughness_texture, 1) == doctest::Approx(100 / 255.0f));
    CHECK(texel(m, l.clearcoat_normal_texture, 2) == doctest::Approx(1.0f));
    CHECK(l.clearcoat_normal_scale == 0.5f);
    CHECK(m.materials[0].ignored.empty());
    CHECK(m.materials[0].normal_texture == -1);  // the coat's map is not the base's

    // Defaults: no coat.
    const LoadedModel bare = load_layers(dir, {{"KHR_materials_clearcoat", json::object()}});
    CHECK_FALSE(bare.materials.at(0).layers.any());
}

TEST_CASE("glTF sheen: colour (sRGB texture) and roughness (alpha) reach the material") {
    const fs::path dir = scratch("layers_sheen");
    const json ext = {{"KHR_materials_sheen",
                       {{"sheenColorFactor", {0.5, 0.25, 2.0}},
                        {"sheenColorTexture", {{"index", 0}}},
                        {"sheenRoughnessFactor", 0.6},
                        {"sheenRoughnessTexture", {{"index", 2}}}}}};
    const LoadedModel m = load_layers(dir, ext, {"KHR_materials_sheen"});
    const PbrLayersDesc& l = m.materials.at(0).layers;
    CHECK(l.sheen_color == Rgb(0.5f, 0.25f, 1.0f));  // clamped to [0, 1]
    CHECK(l.sheen_roughness == doctest::Approx(0.6f));
    CHECK(texel(m, l.sheen_color_texture, 0) == doctest::Approx(srgb_decode(200 / 255.0f)));  // colour: sRGB
    CHECK(texel(m, l.sheen_roughness_texture, 3) == doctest::Approx(64 / 255.0f));
    CHECK(m.materials[0].ignored.empty());
    CHECK(l.clearcoat == 0.0f);
}
