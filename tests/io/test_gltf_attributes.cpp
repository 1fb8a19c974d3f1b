// glTF vertex attributes beyond positions: COLOR_0, TANGENT, morph targets and skins.
#include <doctest/doctest.h>

#include <cmath>

#include "gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

bool near(const Vec3& a, const Vec3& b) { return length(a - b) < 1e-5f; }

}  // namespace

TEST_CASE("glTF COLOR_0 as float RGB and normalized u8 and u16 RGBA") {
    const fs::path dir = scratch("colors");
    Doc d;
    const int pos = d.positions(kTriangle);
    const int f3 = d.accessor(std::vector<float>{1, 0.5f, 0.25f, 0, 1, 0, 0, 0, 1}, 5126, "VEC3", 3);
    const int u8 =
        d.accessor(std::vector<uint8_t>{255, 0, 51, 255, 0, 255, 0, 102, 0, 0, 0, 0}, 5121, "VEC4", 3, true);
    const int u16 = d.accessor(std::vector<uint16_t>{65535, 0, 0, 13107, 0, 0, 0, 0, 0, 0, 0, 65535}, 5123,
                               "VEC4", 3, true);
    d.j["materials"] = json::array({json::object()});
    for (int colors : {f3, u8, u16}) {
        const int mesh = d.mesh(pos, -1, 4, {{"COLOR_0", colors}});
        d.j["meshes"][size_t(mesh)]["primitives"][0]["material"] = 0;
        d.node({{"mesh", mesh}});
    }
    d.node({{"mesh", d.mesh(pos, -1, 4, {{"COLOR_0", f3}})}});  // no material: glTF's default
    const LoadedModel m = load_gltf(d.write(dir / "colors.gltf"));
    REQUIRE(m.meshes.size() == 4);
    CHECK(m.meshes[0].colors == std::vector<Rgb>{Rgb(1, 0.5f, 0.25f), Rgb(0, 1, 0), Rgb(0, 0, 1)});
    CHECK(m.meshes[0].color_alphas.empty());
    CHECK(m.meshes[1].colors[0].z == doctest::Approx(0.2f));
    CHECK(m.meshes[1].color_alphas == std::vector<float>{1.0f, 0.4f, 0.0f});
    CHECK(m.meshes[2].colors[0] == Rgb(1, 0, 0));
    CHECK(m.meshes[2].color_alphas[0] == doctest::Approx(0.2f));
    CHECK(m.meshes[2].color_alphas[2] == 1.0f);
    const MaterialDesc& used = m.materials.at(m.meshes[0].material);
    CHECK(used.vertex_colors);
    const MaterialDesc& fallback = m.materials.at(m.meshes[3].material);
    CHECK(fallback.type == MaterialType::pbr);
    CHECK(fallback.vertex_colors);
    CHECK(fallback.albedo.color == Rgb(1.0f));

    Doc bad;
    bad.node({{"mesh", bad.mesh(bad.positions(kTriangle), -1, 4,
                                {{"COLOR_0", bad.accessor(std::vector<uint8_t>(12, 9), 5121, "VEC4", 3)}})}});
    CHECK(error_of([&] {
              load_gltf(bad.write(dir / "bad.gltf"));
          }).find("COLOR_0: integer colours must be normalized") != std::string::npos);
}

TEST_CASE("glTF TANGENT: read with its handedness and transformed with the node") {
    const fs::path dir = scratch("tangents");
    Doc d;
    const int tan = d.accessor(std::vector<float>{2, 0, 0, 1, 1, 0, 0, -1, 0, 1, 0, 1}, 5126, "VEC4", 3);
    const int mesh = d.mesh(d.positions(kTriangle), -1, 4, {{"TANGENT", tan}});
    d.node({{"mesh", mesh}, {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}}});  // 90 degrees about +Z
    d.node({{"mesh", mesh}, {"scale", {-1, 1, 1}}});                                 // a mirror
    const LoadedModel m = load_gltf(d.write(dir / "t.gltf"));
    REQUIRE(m.meshes.size() == 2);
    const auto& t = m.meshes[0].tangents;
    REQUIRE(t.size() == 3);
    CHECK(near({t[0][0], t[0][1], t[0][2]}, {0, 1, 0}));  // normalised and rotated
    CHECK(t[0][3] == 1.0f);
    CHECK(t[1][3] == -1.0f);
    CHECK(near({t[2][0], t[2][1], t[2][2]}, {-1, 0, 0}));
    const auto& mirrored = m.meshes[1].tangents;
    CHECK(near({mirrored[0][0], mirrored[0][1], mirrored[0][2]}, {-1, 0, 0}));
    CHECK(mirrored[0][3] == -1.0f);  // the mirror flips the bitangent
    CHECK(mirrored[1][3] == 1.0f);
}

TEST_CASE("glTF morph targets apply the mesh's default weights and a node's own weights") {
    const fs::path dir = scratch("morph");
    Doc d;
    const int pos = d.positions(kTriangle);
    const int nrm = d.accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, 5126, "VEC3", 3);
    const int up = d.accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, 5126, "VEC3", 3);
    const int right = d.accessor(std::vector<float>{2, 0, 0, 0, 0, 0, 0, 0, 0}, 5126, "VEC3", 3);
    const int tilt = d.accessor(std::vector<float>{1, 0, -1, 1, 0, -1, 1, 0, -1}, 5126, "VEC3", 3);
    const int mesh = d.mesh(pos, -1, 4, {{"NORMAL", nrm}});
    auto& prim = d.j["meshes"][size_t(mesh)]["primitives"][0];
    prim["targets"] = {{{"POSITION", up}}, {{"POSITION", right}, {"NORMAL", tilt}}};
    d.j["meshes"][size_t(mesh)]["weights"] = {0.5, 0.25};
    d.node({{"mesh", mesh}});
    d.node({{"mesh", mesh}, {"weights", {1, 0}}});
    const LoadedModel m = load_gltf(d.write(dir / "morph.gltf"));
    REQUIRE(m.meshes.size() == 2);
    // Mesh weights: z + 0.5, vertex 0 moves 0.25 * 2 along x; normal (0,0,1) + 0.25 (1,0,-1), renormalised.
    CHECK(near(m.meshes[0].positions[0], {0.5f, 0, 0.5f}));
    CHECK(near(m.meshes[0].positions[1], {1, 0, 0.5f}));
    CHECK(near(m.meshes[0].normals[0], normalize(Vec3(0.25f, 0, 0.75f))));
    // Node weights replace the mesh's.
    CHECK(near(m.meshes[1].positions[0], {0, 0, 1}));
    CHECK(near(m.meshes[1].normals[0], {0, 0, 1}));
}

TEST_CASE("glTF skinned meshes are posed by their joints and not by their own node") {
    const fs::path dir = scratch("skin");
    Doc d;
    const int pos = d.positions(kTriangle);
    const int joints = d.accessor(std::vector<uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, 5121, "VEC4", 3);
    const int weights =
        d.accessor(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, 5126, "VEC4", 3);
    // Inverse bind matrices (column-major): joint 0 identity, joint 1 a translation by (0, 0, -1).
    std::vector<float> ibm(32, 0.0f);
    for (size_t k = 0; k < 4; ++k) ibm[5 * k] = ibm[16 + 5 * k] = 1.0f;
    ibm[16 + 14] = -1.0f;
    const int ibm_acc = d.accessor(ibm, 5126, "MAT4", 2);
    const int mesh = d.mesh(pos, -1, 4, {{"JOINTS_0", joints}, {"WEIGHTS_0", weights}});
    const int joint0 = d.node({{"translation", {10, 0, 0}}}, false);
    const int joint1 = d.node({{"translation", {0, 0, 1}}}, false);
    d.node({{"children", {joint0, joint1}}, {"translation", {0, 5, 0}}});
    d.node({{"mesh", mesh}, {"skin", 0}, {"translation", {100, 100, 100}}});  // ignored for skinned meshes
    d.j["skins"] = {{{"joints", {joint0, joint1}}, {"inverseBindMatrices", ibm_acc}}};
    const LoadedModel m = load_gltf(d.write(dir / "skin.gltf"));
    REQUIRE(m.meshes.size() == 1);
    const auto& p = m.meshes[0].positions;
    CHECK(near(p[0], {10, 5, 0}));  // joint 0: its world matrix, identity bind
    CHECK(near(p[1], {1, 5, 0}));   // joint 1: world (0,5,1) x inverse bind (0,0,-1)
    CHECK(near(p[2], {5, 6, 0}));   // half joint 0 (10,6,0), half joint 1 (0,6,0)
}
