// KHR_materials_iridescence as it reaches MaterialDesc, the messages bad values
// get, and the coloured highlight it renders.
#include <doctest/doctest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "gltf_test_doc.h"
#include "io/scene_parser.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;
using namespace sahara::test::gltf;

namespace {

/// A one-triangle file whose smooth black dielectric material has `extension`
/// as KHR_materials_iridescence (none if null), with one 1x1 image of the texel
/// (255, 128, 40): full weight in R, half way from minimum to maximum thickness in G.
fs::path iridescence_file(const fs::path& dir, const json& extension) {
    json material = {{"pbrMetallicRoughness",
                      {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.1}}}};
    if (!extension.is_null()) material["extensions"] = {{"KHR_materials_iridescence", extension}};
    Doc d = textured_doc(material);
    const uint8_t texel[4] = {255, 128, 40, 255};
    write_image_u8(dir / "film.png", 1, 1, 4, texel);
    d.j["images"] = {{{"uri", "film.png"}}};
    d.j["textures"] = {{{"source", 0}}};
    return d.write(dir / "iridescence.gltf");
}

const json kFilm = {{"iridescenceFactor", 1.0},
                    {"iridescenceTexture", {{"index", 0}}},
                    {"iridescenceIor", 1.8},
                    {"iridescenceThicknessMinimum", 200},
                    {"iridescenceThicknessMaximum", 400},
                    {"iridescenceThicknessTexture", {{"index", 0}, {"texCoord", 1}}}};

/// What a camera ray sees head-on at the triangle of `file` under a white sky.
Stat head_on(const fs::path& file) {
    SceneDesc d = empty_scene(Rgb(1.0f));
    merge_loaded_model(d, load_gltf(file), std::nullopt);
    const Scene scene = build_scene(d);
    return radiance_stats(scene, Ray{{0.3f, 0.3f, 3.0f}, {0, 0, -1}, 0.0f, kInfinity, 0.0f}, scaled(4000), 4);
}

}  // namespace

TEST_CASE("glTF iridescence: factors and linear textures reach the material") {
    const fs::path dir = scratch("iridescence");
    const LoadedModel m = load_gltf(iridescence_file(dir, kFilm));
    const MaterialDesc& mat = m.materials.at(0);
    const IridescenceDesc& film = mat.iridescence;
    CHECK(film.factor == 1.0f);
    CHECK(film.ior == doctest::Approx(1.8f));
    CHECK(film.thickness_min == 200.0f);
    CHECK(film.thickness_max == 400.0f);
    REQUIRE(film.texture >= 0);
    REQUIRE(film.thickness_texture >= 0);
    CHECK(m.textures.at(size_t(film.thickness_texture)).texcoord == 1);
    const Image& image = *m.textures.at(size_t(film.thickness_texture)).image;
    CHECK(image.rgba.at(1) == doctest::Approx(128 / 255.0f));  // data: not sRGB-decoded
    CHECK(mat.ignored.empty());
    CHECK(std::find(mat.extensions.begin(), mat.extensions.end(), "KHR_materials_iridescence") !=
          mat.extensions.end());
    std::vector<std::string> roles;
    for_each_texture_slot(mat, [&](const char* role, int index) {
        if (index == film.thickness_texture) roles.push_back(role);
    });
    CHECK(std::find(roles.begin(), roles.end(), "iridescence thickness") != roles.end());

    // The extension's defaults: no film.
    const IridescenceDesc bare = load_gltf(iridescence_file(dir, json::object())).materials.at(0).iridescence;
    CHECK_FALSE(bare.any());
    CHECK(bare.ior == doctest::Approx(1.3f));
    CHECK(bare.thickness_min == 100.0f);
    CHECK(bare.thickness_max == 400.0f);
}

TEST_CASE("glTF iridescence: bad values are refused naming the file and element") {
    const fs::path dir = scratch("iridescence_bad");
    const auto error_with = [&](const char* key, const json& value) {
        json ext = kFilm;
        ext[key] = value;
        return error_of([&] { load_gltf(iridescence_file(dir, ext)); });
    };
    for (const auto& [key, value] : {std::pair<const char*, json>{"iridescenceFactor", 1.5},
                                     {"iridescenceFactor", "much"},
                                     {"iridescenceIor", 0.9},
                                     {"iridescenceThicknessMinimum", -10},
                                     {"iridescenceThicknessMaximum", "thick"}}) {
        const std::string e = error_with(key, value);
        INFO(key << ": " << e);
        CHECK(e.find("iridescence.gltf") != std::string::npos);
        CHECK(e.find(std::string("materials[0].extensions.KHR_materials_iridescence.") + key) !=
              std::string::npos);
        CHECK(e.find("must be a number") != std::string::npos);
    }
    const std::string missing = error_with("iridescenceThicknessTexture", {{"index", 7}});
    CHECK(missing.find("KHR_materials_iridescence.iridescenceThicknessTexture") != std::string::npos);
    CHECK(missing.find("texture 7 does not exist") != std::string::npos);
}

TEST_CASE("glTF iridescence renders a coloured highlight where the plain file's is grey") {
    const fs::path dir = scratch("iridescence_render");
    const Stat plain = head_on(iridescence_file(dir, nullptr));
    const Stat film = head_on(iridescence_file(dir, kFilm));
    INFO("plain " << plain.mean.x << " " << plain.mean.y << " " << plain.mean.z << " film " << film.mean.x
                  << " " << film.mean.y << " " << film.mean.z);
    // A black dielectric under a white sky reflects its grey Fresnel only.
    CHECK(max_component(plain.mean) - min_component(plain.mean) < 0.005f);
    CHECK(max_component(plain.mean) > 0.03f);
    // 300 nm of a 1.8 film: magenta (red and blue above green) by more than the noise.
    CHECK(film.mean.x > film.mean.y + 0.02f + 4 * (film.se.x + film.se.y));
    CHECK(film.mean.z > film.mean.y + 0.02f + 4 * (film.se.z + film.se.y));
}
