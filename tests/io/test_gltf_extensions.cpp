// glTF material and texture extensions beyond the core: KHR_materials_pbrSpecularGlossiness,
// KHR_materials_specular, EXT_texture_webp, and extensionsRequired.
#include <doctest/doctest.h>

#include "gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

/// A one-triangle document whose material carries only `extensions` (no pbrMetallicRoughness).
Doc doc_with(const json& extensions, const std::vector<std::string>& required = {}) {
    Doc d = textured_doc({{"extensions", extensions}});
    d.j["extensionsUsed"] = json::array();
    for (const auto& [name, value] : extensions.items()) d.j["extensionsUsed"].push_back(name);
    if (!required.empty()) d.j["extensionsRequired"] = required;
    return d;
}

bool near(const Rgb& a, const Rgb& b, float tolerance) { return max_component(abs(a - b)) <= tolerance; }

/// Texel (x, y) of a texture's image, RGB and alpha.
Rgb texel(const TextureDesc& t, int x, int y, float* alpha = nullptr) {
    const float* p = &t.image->rgba[(size_t(y) * size_t(t.image->width) + size_t(x)) * 4];
    if (alpha) *alpha = p[3];
    return {p[0], p[1], p[2]};
}

}  // namespace

TEST_CASE("KHR_materials_pbrSpecularGlossiness factors convert to metallic-roughness") {
    const fs::path dir = scratch("specgloss");
    // A dielectric (specular below 0.04 brightness): its diffuse colour is the base colour.
    json plastic = {{"KHR_materials_pbrSpecularGlossiness",
                     {{"diffuseFactor", {0.2, 0.5, 0.8, 0.6}},
                      {"specularFactor", {0.03, 0.03, 0.03}},
                      {"glossinessFactor", 0.7}}}};
    Doc d = doc_with(plastic, {"KHR_materials_pbrSpecularGlossiness"});
    d.j["materials"][0]["alphaMode"] = "BLEND";
    LoadedModel m = load_gltf(d.write(dir / "plastic.gltf"));
    REQUIRE(m.materials.size() == 1);
    const MaterialDesc& p = m.materials[0];
    CHECK(p.type == MaterialType::pbr);
    CHECK(near(p.albedo.color, Rgb(0.2f, 0.5f, 0.8f) * (0.97f / 0.96f), 1e-5f));  // not glTF's default white
    CHECK(p.metallic == 0.0f);
    CHECK(p.roughness == doctest::Approx(0.3f));
    CHECK(p.alpha == doctest::Approx(0.6f));
    CHECK(p.ignored.empty());
    CHECK(p.extensions == std::vector<std::string>{"KHR_materials_pbrSpecularGlossiness"});

    // The extension's own example, gold: black diffuse, coloured specular -> a metal of that colour.
    json gold = {{"KHR_materials_pbrSpecularGlossiness",
                  {{"diffuseFactor", {0, 0, 0, 1}},
                   {"specularFactor", {1.0, 0.766, 0.336}},
                   {"glossinessFactor", 0.9}}}};
    m = load_gltf(doc_with(gold).write(dir / "gold.gltf"));
    CHECK(m.materials[0].metallic == doctest::Approx(1.0f).epsilon(1e-4));
    CHECK(near(m.materials[0].albedo.color, Rgb(1.0f, 0.766f, 0.336f), 1e-3f));
    CHECK(m.materials[0].roughness == doctest::Approx(0.1f));
}

TEST_CASE("KHR_materials_pbrSpecularGlossiness textures are converted texel by texel") {
    const fs::path dir = scratch("specgloss_tex");
    const std::vector<uint8_t> diffuse_png = tiny_png(dir);  // red, (0,128,0,128); blue, white
    // Specular-glossiness: left column a dielectric grey (sRGB 50 -> 0.03), right column
    // a bright metal-like specular; glossiness (A) 1 times the factor 0.8. (An alpha below 1
    // would not survive the PNG round trip exactly: the writer and reader associate it.)
    const uint8_t sg_px[16] = {50, 50, 50, 255, 255, 255, 255, 255, 50, 50, 50, 255, 255, 255, 255, 255};
    write_image_u8(dir / "sg.png", 2, 2, 4, sg_px);
    json ext = {{"KHR_materials_pbrSpecularGlossiness",
                 {{"diffuseTexture", {{"index", 0}}},
                  {"specularGlossinessTexture", {{"index", 1}}},
                  {"diffuseFactor", {1, 1, 1, 1}},
                  {"specularFactor", {1, 1, 1}},
                  {"glossinessFactor", 0.8}}}};
    Doc d = doc_with(ext);
    d.j["materials"][0]["alphaMode"] = "MASK";
    d.j["images"] = {{{"uri", "data:image/png;base64," + base64(diffuse_png)}}, {{"uri", "sg.png"}}};
    d.j["textures"] = {{{"source", 0}}, {{"source", 1}}};
    const LoadedModel m = load_gltf(d.write(dir / "sg.gltf"));
    const MaterialDesc& mat = m.materials.at(0);
    REQUIRE(mat.albedo.kind == ColorSource::Kind::texture);
    REQUIRE(mat.metallic_roughness_texture >= 0);
    CHECK(mat.albedo.color == Rgb(1.0f));
    CHECK(mat.metallic == 1.0f);
    CHECK(mat.roughness == 1.0f);
    CHECK(mat.alpha_texture == mat.albedo.texture);
    const TextureDesc& base = m.textures.at(size_t(mat.albedo.texture));
    const TextureDesc& mr = m.textures.at(size_t(mat.metallic_roughness_texture));
    REQUIRE(base.image->width == 2);
    // Top left: dielectric, base = red diffuse; top right: diffuse alpha kept, white specular -> metal.
    float alpha = 0;
    CHECK(near(texel(base, 0, 0, &alpha), Rgb(1, 0, 0), 0.02f));
    CHECK(alpha == doctest::Approx(1.0f));
    CHECK(near(texel(mr, 0, 0), Rgb(1, 0.2f, 0), 0.01f));  // G roughness = 1 - 0.8, B metallic 0
    CHECK(near(texel(base, 1, 0, &alpha), Rgb(1, 1, 1), 0.01f));
    CHECK(alpha == doctest::Approx(128 / 255.0f));
    CHECK(texel(mr, 1, 0).z == doctest::Approx(1.0f));    // metallic
    CHECK(near(texel(base, 0, 1), Rgb(0, 0, 1), 0.02f));  // bottom left: blue diffuse
}

TEST_CASE("KHR_materials_specular reads strength and colour with their textures") {
    const fs::path dir = scratch("specular");
    json ext = {{"KHR_materials_specular",
                 {{"specularFactor", 0.5},
                  {"specularTexture", {{"index", 0}}},
                  {"specularColorFactor", {2.0, 1.0, 0.5}},
                  {"specularColorTexture", {{"index", 1}}}}}};
    Doc d = doc_with(ext, {"KHR_materials_specular"});
    d.j["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.3, 0.3, 0.3, 1}}};
    const std::vector<uint8_t> png = tiny_png(dir);
    d.j["images"] = {{{"uri", "data:image/png;base64," + base64(png)}}};
    d.j["samplers"] = {{{"wrapS", 33071}}};
    d.j["textures"] = {{{"source", 0}}, {{"source", 0}, {"sampler", 0}}};
    const LoadedModel m = load_gltf(d.write(dir / "s.gltf"));
    const MaterialDesc& mat = m.materials.at(0);
    CHECK(mat.specular == 0.5f);
    CHECK(mat.specular_color == Rgb(2.0f, 1.0f, 0.5f));  // above 1 is allowed: F0 is clamped where it is used
    REQUIRE(mat.specular_texture >= 0);
    REQUIRE(mat.specular_color_texture >= 0);
    // The strength texture is data (linear), the colour texture sRGB.
    CHECK(texel(m.textures.at(size_t(mat.specular_texture)), 1, 0).y == doctest::Approx(128 / 255.0f));
    CHECK(texel(m.textures.at(size_t(mat.specular_color_texture)), 1, 0).y ==
          doctest::Approx(srgb_decode(128 / 255.0f)));
    CHECK(mat.albedo.color == Rgb(0.3f));
    CHECK(mat.ignored.empty());
    CHECK(mat.extensions == std::vector<std::string>{"KHR_materials_specular"});
}

TEST_CASE("EXT_texture_webp: the WebP source loads and an unreadable one falls back to source") {
    const fs::path dir = scratch("webp");
    const uint8_t green[16] = {0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255};
    const uint8_t red[16] = {255, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255};
    write_image_u8(dir / "green.webp", 2, 2, 4, green);
    write_image_u8(dir / "red.png", 2, 2, 4, red);
    write_text(dir / "broken.webp", "RIFF not really a webp file");
    const auto load = [&](const json& texture, const std::vector<std::string>& required) {
        Doc d = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
        d.j["images"] = {{{"uri", "red.png"}}, {{"uri", "green.webp"}}, {{"uri", "broken.webp"}}};
        d.j["textures"] = {texture};
        d.j["extensionsUsed"] = {"EXT_texture_webp"};
        if (!required.empty()) d.j["extensionsRequired"] = required;
        return load_gltf(d.write(dir / "w.gltf"));
    };
    const auto color = [](const LoadedModel& m) {
        REQUIRE(m.materials.at(0).albedo.kind == ColorSource::Kind::texture);
        return texel(m.textures.at(size_t(m.materials[0].albedo.texture)), 0, 0);
    };
    const json webp_green = {{"EXT_texture_webp", {{"source", 1}}}};
    const json webp_broken = {{"EXT_texture_webp", {{"source", 2}}}};
    const LoadedModel with_fallback = load({{"source", 0}, {"extensions", webp_green}}, {});
    CHECK(near(color(with_fallback), Rgb(0, 1, 0), 0.05f));
    CHECK(with_fallback.materials[0].extensions == std::vector<std::string>{"EXT_texture_webp"});
    CHECK(near(color(load({{"extensions", webp_green}}, {"EXT_texture_webp"})), Rgb(0, 1, 0), 0.05f));
    const LoadedModel fell_back = load({{"source", 0}, {"extensions", webp_broken}}, {});
    CHECK(near(color(fell_back), Rgb(1, 0, 0), 1e-6f));
    CHECK(fell_back.materials[0].extensions.empty());  // the PNG was used
    // Without a fallback an unreadable WebP image is an error naming the texture's extension.
    const std::string error = error_of([&] { load({{"extensions", webp_broken}}, {"EXT_texture_webp"}); });
    CHECK(error.find("EXT_texture_webp") != std::string::npos);
}

TEST_CASE("extensionsRequired: the new extensions are accepted and an unknown one is named") {
    const fs::path dir = scratch("required");
    Doc d = doc_with({{"KHR_materials_unlit", json::object()}},
                     {"KHR_materials_unlit", "KHR_materials_specular", "KHR_materials_pbrSpecularGlossiness",
                      "EXT_texture_webp"});
    CHECK_NOTHROW(load_gltf(d.write(dir / "ok.gltf")));
    d.j["extensionsRequired"].push_back("KHR_materials_made_up");
    const std::string error = error_of([&] { load_gltf(d.write(dir / "bad.gltf")); });
    CHECK(error.find("extensionsRequired") != std::string::npos);
    CHECK(error.find("KHR_materials_made_up is not supported") != std::string::npos);
}
