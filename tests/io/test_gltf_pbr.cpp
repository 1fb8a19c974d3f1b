// glTF metallic-roughness materials and their extensions as they reach MaterialDesc.
#include <doctest/doctest.h>

#include <cmath>

#include "gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

/// A 1x1 RGBA PNG of the given bytes, as a data URI.
std::string pixel_png_uri(const fs::path& dir, const std::string& name, std::vector<uint8_t> rgba) {
    const fs::path file = dir / (name + ".png");
    write_image_u8(file, 1, 1, 4, rgba.data());
    return "data:image/png;base64," + base64(read_all(file));
}

/// Loads a one-triangle file whose material is `material`, with images 0..3:
/// grey 128 (opaque), (0, 64, 255), (128, 128, 255) and (200, 0, 0).
LoadedModel load_material(const fs::path& dir, const json& material) {
    Doc d = textured_doc(material);
    d.j["images"] = {{{"uri", pixel_png_uri(dir, "grey", {128, 128, 128, 255})}},
                     {{"uri", pixel_png_uri(dir, "mr", {0, 64, 255, 255})}},
                     {{"uri", pixel_png_uri(dir, "normal", {128, 128, 255, 255})}},
                     {{"uri", pixel_png_uri(dir, "red", {200, 0, 0, 255})}}};
    d.j["textures"] = {{{"source", 0}}, {{"source", 1}}, {{"source", 2}}, {{"source", 3}}};
    return load_gltf(d.write(dir / "pbr.gltf"));
}

float texel(const LoadedModel& m, int texture, int channel) {
    return m.textures.at(size_t(texture)).image->rgba.at(size_t(channel));
}

}  // namespace

TEST_CASE("glTF pbr: every core material input reaches the material description") {
    const fs::path dir = scratch("pbr_core");
    const json material = {{"name", "paint"},
                           {"pbrMetallicRoughness",
                            {{"baseColorFactor", {0.5, 0.25, 1, 1}},
                             {"baseColorTexture", {{"index", 0}}},
                             {"metallicFactor", 0.25},
                             {"roughnessFactor", 0.75},
                             {"metallicRoughnessTexture", {{"index", 1}, {"texCoord", 1}}}}},
                           {"normalTexture", {{"index", 2}, {"scale", 0.5}}},
                           {"occlusionTexture", {{"index", 3}}},
                           {"emissiveFactor", {0.5, 0.25, 1}},
                           {"emissiveTexture", {{"index", 3}}},
                           {"doubleSided", true},
                           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 2}}}}}};
    const LoadedModel m = load_material(dir, material);
    REQUIRE(m.materials.size() == 1);
    const MaterialDesc& p = m.materials[0];
    CHECK(p.name == "paint");
    CHECK(p.type == MaterialType::pbr);
    CHECK(p.albedo.kind == ColorSource::Kind::texture);
    CHECK(p.albedo.color == Rgb(0.5f, 0.25f, 1));
    CHECK(texel(m, p.albedo.texture, 0) == doctest::Approx(srgb_decode(128 / 255.0f)));  // colour: sRGB
    CHECK(p.metallic == 0.25f);
    CHECK(p.roughness == 0.75f);
    REQUIRE(p.metallic_roughness_texture >= 0);
    CHECK(m.textures[size_t(p.metallic_roughness_texture)].texcoord == 1);
    CHECK(texel(m, p.metallic_roughness_texture, 1) == doctest::Approx(64 / 255.0f));  // data: linear
    CHECK(texel(m, p.metallic_roughness_texture, 2) == 1.0f);
    REQUIRE(p.normal_texture >= 0);
    CHECK(p.normal_scale == 0.5f);
    CHECK(texel(m, p.normal_texture, 0) == doctest::Approx(128 / 255.0f));
    CHECK(p.radiance.kind == ColorSource::Kind::texture);
    CHECK(p.radiance.color == Rgb(1, 0.5f, 2));  // factor x strength
    CHECK(texel(m, p.radiance.texture, 0) == doctest::Approx(srgb_decode(200 / 255.0f)));
    CHECK(p.double_sided);
    CHECK(p.alpha == 1.0f);  // OPAQUE
    CHECK(p.alpha_texture == -1);
    // Occlusion is ignored: textures are base colour, metallic-roughness, normal and emissive only.
    CHECK(m.textures.size() == 4);
}

TEST_CASE("glTF pbr: defaults follow the specification") {
    const fs::path dir = scratch("pbr_defaults");
    const LoadedModel m = load_material(dir, json::object());
    const MaterialDesc& p = m.materials.at(0);
    CHECK(p.type == MaterialType::pbr);
    CHECK(p.albedo.kind == ColorSource::Kind::constant);
    CHECK(p.albedo.color == Rgb(1.0f));
    CHECK(p.metallic == 1.0f);
    CHECK(p.roughness == 1.0f);
    CHECK(p.ior == 1.5f);
    CHECK(p.transmission == 0.0f);
    CHECK(p.normal_texture == -1);
    CHECK(p.metallic_roughness_texture == -1);
    CHECK(max_component(p.radiance.color) == 0.0f);
    CHECK_FALSE(p.double_sided);  // glTF's default, unlike scene files
    CHECK(p.alpha == 1.0f);
    CHECK_FALSE(p.alpha_cutoff.has_value());
    CHECK_FALSE(p.vertex_colors);
    CHECK(m.textures.empty());
}

TEST_CASE("glTF alpha modes: OPAQUE ignores alpha and MASK cuts at 0.5 by default and BLEND is stochastic") {
    const fs::path dir = scratch("pbr_alpha");
    const json base = {{"baseColorFactor", {1, 1, 1, 0.4}}, {"baseColorTexture", {{"index", 0}}}};
    const LoadedModel opaque = load_material(dir, {{"pbrMetallicRoughness", base}, {"alphaMode", "OPAQUE"}});
    CHECK(opaque.materials[0].alpha == 1.0f);
    CHECK(opaque.materials[0].alpha_texture == -1);
    const LoadedModel mask = load_material(dir, {{"pbrMetallicRoughness", base}, {"alphaMode", "MASK"}});
    CHECK(mask.materials[0].alpha == doctest::Approx(0.4f));
    REQUIRE(mask.materials[0].alpha_cutoff.has_value());
    CHECK(*mask.materials[0].alpha_cutoff == 0.5f);
    CHECK(mask.materials[0].alpha_texture == mask.materials[0].albedo.texture);
    const LoadedModel blend = load_material(dir, {{"pbrMetallicRoughness", base}, {"alphaMode", "BLEND"}});
    CHECK(blend.materials[0].alpha == doctest::Approx(0.4f));
    CHECK_FALSE(blend.materials[0].alpha_cutoff.has_value());
    CHECK(blend.materials[0].alpha_texture >= 0);
    const std::string bad = error_of([&] { load_material(dir, {{"alphaMode", "ADD"}}); });
    CHECK(bad.find("materials[0].alphaMode: unknown mode 'ADD'") != std::string::npos);
}

TEST_CASE("glTF transmission and ior and volume extensions") {
    const fs::path dir = scratch("pbr_transmission");
    const json ext = {
        {"KHR_materials_transmission",
         {{"transmissionFactor", 0.6}, {"transmissionTexture", {{"index", 3}}}}},
        {"KHR_materials_ior", {{"ior", 1.33}}},
        {"KHR_materials_volume",
         {{"thicknessFactor", 1}, {"attenuationDistance", 2}, {"attenuationColor", {1, 0.5, 0.25}}}}};
    const LoadedModel m = load_material(dir, {{"extensions", ext}});
    const MaterialDesc& p = m.materials.at(0);
    CHECK(p.transmission == doctest::Approx(0.6f));
    REQUIRE(p.transmission_texture >= 0);
    CHECK(texel(m, p.transmission_texture, 0) == doctest::Approx(200 / 255.0f));  // data: linear
    CHECK(p.ior == doctest::Approx(1.33f));
    CHECK(p.attenuation_distance == 2.0f);
    CHECK(p.attenuation_color == Rgb(1, 0.5f, 0.25f));

    // An ior below 1 is not physical: warned about, the default kept. No volume: no attenuation.
    const LoadedModel low = load_material(dir, {{"extensions", {{"KHR_materials_ior", {{"ior", 0.5}}}}}});
    CHECK(low.materials[0].ior == 1.5f);
    CHECK(std::isinf(low.materials[0].attenuation_distance));
}
