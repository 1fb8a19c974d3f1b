// KHR_materials_anisotropy and the TANGENT attribute as they reach MaterialDesc
// and TriangleMesh, with the messages bad values get.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

/// A one-triangle file whose material has `extension` as KHR_materials_anisotropy,
/// with one 1x1 image of the texel (200, 100, 50).
fs::path anisotropy_file(const fs::path& dir, const json& extension) {
    Doc d = textured_doc({{"extensions", {{"KHR_materials_anisotropy", extension}}}});
    const uint8_t texel[4] = {200, 100, 50, 255};
    write_image_u8(dir / "direction.png", 1, 1, 4, texel);
    d.j["images"] = {{{"uri", "direction.png"}}};
    d.j["textures"] = {{{"source", 0}}};
    d.j["extensionsRequired"] = {"KHR_materials_anisotropy"};
    return d.write(dir / "anisotropy.gltf");
}

}  // namespace

TEST_CASE("glTF anisotropy: strength and rotation and a linear direction texture reach the material") {
    const fs::path dir = scratch("anisotropy");
    const LoadedModel m = load_gltf(anisotropy_file(
        dir,
        {{"anisotropyStrength", 0.6}, {"anisotropyRotation", 1.5}, {"anisotropyTexture", {{"index", 0}}}}));
    const MaterialDesc& mat = m.materials.at(0);
    CHECK(mat.anisotropy == doctest::Approx(0.6f));
    CHECK(mat.anisotropy_rotation == doctest::Approx(1.5f));
    REQUIRE(mat.anisotropy_texture >= 0);
    const Image& image = *m.textures.at(size_t(mat.anisotropy_texture)).image;
    CHECK(image.rgba.at(0) == doctest::Approx(200 / 255.0f));  // a direction is data: not sRGB-decoded
    CHECK(image.rgba.at(2) == doctest::Approx(50 / 255.0f));
    CHECK(mat.ignored.empty());
    CHECK(std::find(mat.extensions.begin(), mat.extensions.end(), "KHR_materials_anisotropy") !=
          mat.extensions.end());
    // The texture is one of the material's slots: renumbering and `sahara info` see it.
    std::vector<std::string> roles;
    for_each_texture_slot(mat, [&](const char* role, int index) {
        if (index == mat.anisotropy_texture) roles.push_back(role);
    });
    CHECK(std::find(roles.begin(), roles.end(), "anisotropy") != roles.end());

    // Defaults: isotropic.
    const LoadedModel bare = load_gltf(anisotropy_file(dir, json::object()));
    CHECK(bare.materials.at(0).anisotropy == 0.0f);
    CHECK(bare.materials.at(0).anisotropy_rotation == 0.0f);
    CHECK(bare.materials.at(0).anisotropy_texture == -1);
}

TEST_CASE("glTF anisotropy: bad values are clamped or refused naming the file and element") {
    const fs::path dir = scratch("anisotropy_bad");
    CHECK(load_gltf(anisotropy_file(dir, {{"anisotropyStrength", 1.5}})).materials.at(0).anisotropy == 1.0f);
    CHECK(load_gltf(anisotropy_file(dir, {{"anisotropyStrength", -2}})).materials.at(0).anisotropy == 0.0f);
    const std::string missing = error_of([&] {
        load_gltf(anisotropy_file(dir, {{"anisotropyTexture", {{"index", 7}}}}));
    });
    CHECK(missing.find("anisotropy.gltf") != std::string::npos);
    CHECK(missing.find("KHR_materials_anisotropy.anisotropyTexture") != std::string::npos);
    CHECK(missing.find("texture 7 does not exist") != std::string::npos);
    const std::string text = error_of([&] {
        load_gltf(anisotropy_file(dir, {{"anisotropyRotation", "left"}}));
    });
    CHECK(text.find("KHR_materials_anisotropy.anisotropyRotation") != std::string::npos);
    CHECK(text.find("must be a number") != std::string::npos);
}

TEST_CASE("glTF TANGENT: w must be 1 or -1 and every component finite") {
    const fs::path dir = scratch("tangent_bad");
    const auto with_tangents = [&](const std::vector<float>& t) {
        Doc d;
        const int tan = d.accessor(t, 5126, "VEC4", 3);
        d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 4, {{"TANGENT", tan}})}});
        return d.write(dir / "t.gltf");
    };
    CHECK(load_gltf(with_tangents({1, 0, 0, 1, 1, 0, 0, -1, 0, 1, 0, 1})).meshes.at(0).tangents.size() == 3);
    const std::string half = error_of([&] {
        load_gltf(with_tangents({1, 0, 0, 1, 1, 0, 0, 0.5f, 0, 1, 0, 1}));
    });
    CHECK(half.find("t.gltf") != std::string::npos);
    CHECK(half.find("meshes[0].primitives[0].attributes.TANGENT") != std::string::npos);
    CHECK(half.find("element 1 has w = 0.5") != std::string::npos);
    const std::string nan = error_of([&] {
        load_gltf(with_tangents({1, 0, 0, 1, std::nanf(""), 0, 0, 1, 0, 1, 0, 1}));
    });
    CHECK(nan.find("t.gltf: accessors[0]: element 1") != std::string::npos);  // the accessor reader's check
    CHECK(nan.find("not a finite number") != std::string::npos);
}
