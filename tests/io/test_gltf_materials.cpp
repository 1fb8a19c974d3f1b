#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "gltf_test_doc.h"
#include "base/log.h"
#include "scene/texture.h"

using namespace sahara;
using namespace sahara::test::gltf;

TEST_CASE("glTF materials: base colour factor x texture / alpha modes / emission / sRGB decoding") {
    const fs::path dir = scratch("materials");
    const std::vector<uint8_t> png = tiny_png(dir);
    const json material = {{"pbrMetallicRoughness",
                            {{"baseColorFactor", {0.5, 1, 1, 0.8}}, {"baseColorTexture", {{"index", 0}}}}},
                           {"alphaMode", "MASK"},
                           {"alphaCutoff", 0.3},
                           {"emissiveFactor", {1, 0.5, 0}},
                           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}};
    Doc d = textured_doc(material);
    d.j["images"] = {{{"uri", "data:image/png;base64," + base64(png)}}};
    d.j["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}}};
    d.j["textures"] = {{{"source", 0}, {"sampler", 0}}};
    const LoadedModel m = load_gltf(d.write(dir / "mat.gltf"));
    REQUIRE(m.materials.size() == 1);
    const MaterialDesc& mat = m.materials[0];
    CHECK(mat.type == MaterialType::pbr);  // emission adds to the reflection, not instead of it
    CHECK(mat.radiance.color == Rgb(4, 2, 0));
    CHECK(mat.radiance.kind == ColorSource::Kind::constant);
    CHECK(mat.alpha == doctest::Approx(0.8f));
    REQUIRE(mat.alpha_cutoff.has_value());
    CHECK(*mat.alpha_cutoff == doctest::Approx(0.3f));
    REQUIRE(mat.albedo.kind == ColorSource::Kind::texture);
    CHECK(mat.albedo.color == Rgb(0.5f, 1, 1));
    CHECK(mat.alpha_texture == mat.albedo.texture);
    REQUIRE(m.textures.size() == 1);
    const TextureDesc& t = m.textures[0];
    CHECK(t.wrap_u == WrapMode::clamp);
    CHECK(t.wrap_v == WrapMode::mirror);
    const Image& img = *t.image;
    REQUIRE(img.width == 2);
    CHECK(img.rgba[0] == doctest::Approx(1.0f));                       // top-left red, row 0 = top
    CHECK(img.rgba[5] == doctest::Approx(srgb_decode(128 / 255.0f)));  // sRGB decoded
    CHECK(img.rgba[5] == doctest::Approx(0.2158605f).epsilon(1e-4));
    CHECK(img.rgba[7] == doctest::Approx(128 / 255.0f));  // alpha stays linear
    CHECK(img.rgba[10] == doctest::Approx(1.0f));         // bottom-left blue

    // The same image from a bufferView (as in .glb files), opaque mode.
    Doc v = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    const size_t at = v.blob.add(png);
    v.j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", png.size()}});
    v.j["images"] = {{{"bufferView", v.j["bufferViews"].size() - 1}, {"mimeType", "image/png"}}};
    v.j["textures"] = {{{"source", 0}}};
    const LoadedModel mv = load_gltf(v.write(dir / "view.gltf"));
    CHECK(mv.materials[0].alpha == 1.0f);
    CHECK(mv.materials[0].alpha_texture == -1);
    CHECK(mv.materials[0].type == MaterialType::pbr);
    CHECK(!mv.materials[0].alpha_cutoff.has_value());
    CHECK(mv.textures.at(0).image->rgba == img.rgba);
}

TEST_CASE("KHR_texture_transform is rewritten for sahara's v-up uvs") {
    const fs::path dir = scratch("ktt");
    const std::vector<uint8_t> png = tiny_png(dir);
    const float off[2] = {0.25f, 0.125f}, scl[2] = {2.0f, 3.0f}, rot = 0.4f;
    json ktt = {{"offset", {off[0], off[1]}}, {"scale", {scl[0], scl[1]}}, {"rotation", rot}};
    json info = {{"index", 0}, {"extensions", {{"KHR_texture_transform", ktt}}}};
    Doc d = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", info}}}});
    write_bytes(dir / "tiny file.png", png);
    d.j["images"] = {{{"uri", "tiny%20file.png"}}};
    d.j["textures"] = {{{"source", 0}}};
    const LoadedModel m = load_gltf(d.write(dir / "ktt.gltf"));
    REQUIRE(m.textures.size() == 1);
    const TextureDesc& t = m.textures[0];
    // For a few glTF uvs: the texel row/column glTF addresses must equal sahara's lookup.
    for (const auto& [u, vg] :
         std::vector<std::pair<float, float>>{{0.1f, 0.2f}, {0.7f, 0.9f}, {0.5f, 0.0f}}) {
        // glTF: t = offset + R * (scale * uv) with R = [cos sin; -sin cos], the matrix
        // of the extension's worked example ("offset [0, 1], rotation pi/2, scale 0.5:
        // the lower left quadrant rotated clockwise") and of the Khronos sample viewer;
        // row = t.y * height.
        const float su = scl[0] * u, sv = scl[1] * vg;
        const float tu = off[0] + std::cos(rot) * su + std::sin(rot) * sv;
        const float tv = off[1] - std::sin(rot) * su + std::cos(rot) * sv;
        // sahara (scene_desc.h, scene/texture.cpp): uv = (u, 1 - vg);
        // uv' = offset + [cos sin; -sin cos] * (scale * uv); row = (1 - uv'.y) * height.
        const float xu = t.uv_scale.x * u, xv = t.uv_scale.y * (1 - vg);
        const float pu = t.uv_offset.x + std::cos(t.uv_rotation) * xu + std::sin(t.uv_rotation) * xv;
        const float pv = t.uv_offset.y - std::sin(t.uv_rotation) * xu + std::cos(t.uv_rotation) * xv;
        CHECK(pu == doctest::Approx(tu).epsilon(1e-5));
        CHECK(1 - pv == doctest::Approx(tv).epsilon(1e-5));
    }
}

TEST_CASE("glTF and OBJ uvs reach the texels their formats mean through scene/texture.h") {
    // tiny_png: top row red, (0,128,0); bottom row blue, white. uv 0.25/0.75 hit texel centres.
    const fs::path dir = scratch("texels");
    const std::vector<uint8_t> png = tiny_png(dir);
    const Rgb red(1, 0, 0), blue(0, 0, 1), green(0, srgb_decode(128 / 255.0f), 0);
    auto sample = [](const LoadedModel& m, size_t vertex) {
        const TriangleMesh& mesh = m.meshes.at(0);
        return sample_texture_rgb(m.textures.at(0), mesh.uvs.at(vertex));
    };
    auto near = [](Rgb a, Rgb b) { return length(a - b) < 1e-4f; };

    // glTF: v = 0 is the top row, so uv (0.25, 0.25) is the top-left texel (red).
    const json spec_example = {{"offset", {0, 1}}, {"rotation", std::numbers::pi / 2}, {"scale", {0.5, 0.5}}};
    for (const json& ktt : {json(nullptr), json{{"offset", {0.5, 0}}},
                            json{{"rotation", std::numbers::pi / 2}}, spec_example}) {
        CAPTURE(ktt.dump());
        Doc d;
        const int uv =
            d.accessor(std::vector<float>{0.25f, 0.25f, 0.75f, 0.25f, 0.25f, 0.75f}, 5126, "VEC2", 3);
        d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 4, {{"TEXCOORD_0", uv}})}});
        d.j["meshes"][0]["primitives"][0]["material"] = 0;
        json info = {{"index", 0}};
        if (!ktt.is_null()) info["extensions"] = {{"KHR_texture_transform", ktt}};
        d.j["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", info}}}}};
        d.j["images"] = {{{"uri", "data:image/png;base64," + base64(png)}}};
        d.j["textures"] = {{{"source", 0}}};
        const LoadedModel m = load_gltf(d.write(dir / "t.gltf"));
        if (ktt.is_null()) {
            CHECK(near(sample(m, 0), red));
            CHECK(near(sample(m, 1), green));  // (0.75, 0.25): top right
            CHECK(near(sample(m, 2), blue));   // (0.25, 0.75): bottom left
        } else if (ktt == spec_example) {
            // The extension's example: "the lower left quadrant of the image, rotated clockwise",
            // in sahara's v-up uvs u' and v' in [0, 0.5]; the other direction leaves the image.
            const TextureDesc& t = m.textures.at(0);
            for (const auto& [u, vg] : std::vector<std::pair<float, float>>{{0, 0}, {1, 0}, {0, 1}, {1, 1}}) {
                const float xu = t.uv_scale.x * u, xv = t.uv_scale.y * (1 - vg);
                const float c = std::cos(t.uv_rotation), s = std::sin(t.uv_rotation);
                const float pu = t.uv_offset.x + c * xu + s * xv, pv = t.uv_offset.y - s * xu + c * xv;
                CHECK(pu == doctest::Approx(std::clamp(pu, 0.0f, 0.5f)).epsilon(1e-5));
                CHECK(pv == doctest::Approx(std::clamp(pv, 0.0f, 0.5f)).epsilon(1e-5));
            }
            // glTF's u axis runs up the quadrant's left edge: (1, 0) lands at the top of it.
            const float c = std::cos(t.uv_rotation), s = std::sin(t.uv_rotation);
            CHECK(t.uv_offset.x + c * t.uv_scale.x + s * t.uv_scale.y == doctest::Approx(0.0f).scale(1));
            CHECK(t.uv_offset.y - s * t.uv_scale.x + c * t.uv_scale.y == doctest::Approx(0.5f));
        } else if (ktt.contains("offset")) {
            CHECK(near(sample(m, 0), green));  // u + 0.5
        } else {
            // glTF rotation pi/2: t = [cos sin; -sin cos] p = (0.25, -0.25) -> wraps to (0.25, 0.75):
            // bottom left (the opposite direction would give the top right, green).
            CHECK(near(sample(m, 0), blue));
        }
    }

    // OBJ: v = 0 is the bottom row, so vt 0.25 0.25 is the bottom-left texel (blue).
    write_text(dir / "t.mtl", "newmtl m\nmap_Kd tiny.png\n");
    write_text(dir / "t.obj",
               "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.25\nvt 0.75 0.75\nvt 0.25 0.75\n"
               "usemtl m\nf 1/1 2/2 3/3\n");
    const LoadedModel obj = load_obj(dir / "t.obj");
    CHECK(near(sample(obj, 0), blue));
    CHECK(near(sample(obj, 1), green));  // (0.75, 0.75): top right
    CHECK(near(sample(obj, 2), red));    // (0.25, 0.75): top left
}

TEST_CASE("glTF: the material's TEXCOORD set / normalized byte normals / u8 and u32 indices") {
    const fs::path dir = scratch("sets");
    Doc d = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}}}}});
    d.j["images"] = {{{"uri", "data:image/png;base64," + base64(tiny_png(dir))}}};
    d.j["textures"] = {{{"source", 0}}};
    auto& attrs = d.j["meshes"][0]["primitives"][0]["attributes"];
    attrs["TEXCOORD_1"] = d.accessor(std::vector<uint8_t>{0, 0, 51, 0, 0, 255, 0, 0}, 5121, "VEC2", 3, true);
    // Signed normalized bytes: -127 maps to -1 exactly, 127 to 1.
    attrs["NORMAL"] =
        d.accessor(std::vector<int8_t>{0, 0, 127, 0, 0, 127, 0, -127, 0, 0}, 5120, "VEC3", 3, true);
    d.j["meshes"][0]["primitives"][0]["indices"] =
        d.accessor(std::vector<uint32_t>{2, 1, 0}, 5125, "SCALAR", 3);
    const LoadedModel m = load_gltf(d.write(dir / "sets.gltf"));
    const TriangleMesh& mesh = m.meshes.at(0);
    REQUIRE(mesh.uvs.size() == 3);
    REQUIRE(mesh.uvs1.size() == 3);
    CHECK(m.textures.at(0).texcoord == 1);
    CHECK(mesh.uvs[1].x == 1.0f);                    // TEXCOORD_0
    CHECK(mesh.uvs1[1].x == doctest::Approx(0.2f));  // 51/255 from TEXCOORD_1
    CHECK(mesh.uvs1[2].y == 0.0f);                   // v_gltf = 1 -> 0
    CHECK(mesh.uvs1[1].y == 1.0f);                   // v_gltf = 0 -> 1
    CHECK(mesh.normals[2] == Vec3(0, -1, 0));
    CHECK(mesh.indices == std::vector<uint32_t>{2, 1, 0});
}

TEST_CASE("glTF materials: a negative emissiveStrength emits nothing and is warned about") {
    const fs::path dir = scratch("negative_strength");
    const json material = {{"emissiveFactor", {1, 1, 1}},
                           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -3}}}}}};
    Doc d = textured_doc(material);
    const int warnings = warning_count();
    const LoadedModel m = load_gltf(d.write(dir / "negative.gltf"));
    REQUIRE(m.materials.size() == 1);
    CHECK(m.materials[0].radiance.color == Rgb(0.0f));
    CHECK(warning_count() == warnings + 1);
}
