#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>

#include "base/error.h"
#include "base/log.h"
#include "io/image_bytes.h"
#include "io/image_io.h"
#include "io/mesh_utils.h"
#include "io/model_loader.h"
#include "gltf_test_doc.h"
#include "mesh_fixtures.h"
#include "scene/texture.h"
#include "test_data.h"

using namespace sahara;
using namespace sahara::test::gltf;
using sahara::test::kTestData;
using sahara::test::make_icosphere;

namespace {

/// glTF node matrix from the JSON (column-major `matrix`, else T * R * S).
Mat4 node_matrix(const json& n) {
    Mat4 m;
    if (n.contains("matrix")) {
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c)
                m.m[size_t(r)][size_t(c)] = n["matrix"][size_t(c * 4 + r)].get<double>();
        return m;
    }
    if (n.contains("translation"))
        m = Mat4::translate({n["translation"][0], n["translation"][1], n["translation"][2]});
    if (n.contains("rotation")) {
        const auto& q = n["rotation"];
        m = m * Mat4::rotate_quaternion(q[0], q[1], q[2], q[3]);
    }
    if (n.contains("scale")) m = m * Mat4::scale({n["scale"][0], n["scale"][1], n["scale"][2]});
    return m;
}

/// Box around the 8 corners of every drawn POSITION accessor's min/max, each
/// transformed by its node's world matrix: exact when rotations are multiples
/// of 90 degrees, otherwise a superset of the true bounds.
Bounds3 corner_bounds(const json& j) {
    Bounds3 b;
    std::vector<std::pair<int, Mat4>> stack;
    for (const auto& r : j["scenes"][j.value("scene", 0)]["nodes"]) stack.emplace_back(r.get<int>(), Mat4());
    while (!stack.empty()) {
        auto [i, parent] = stack.back();
        stack.pop_back();
        const json& n = j["nodes"][size_t(i)];
        const Mat4 world = parent * node_matrix(n);
        if (n.contains("mesh"))
            for (const auto& prim : j["meshes"][n["mesh"].get<size_t>()]["primitives"]) {
                const json& acc = j["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
                for (int c = 0; c < 8; ++c) {
                    Vec3 p;
                    for (int k = 0; k < 3; ++k)
                        p[k] = acc[(c >> k) & 1 ? "max" : "min"][size_t(k)].get<float>();
                    b.extend(world.apply_point(p));
                }
            }
        for (const auto& c : n.value("children", json::array())) stack.emplace_back(c.get<int>(), world);
    }
    return b;
}

/// Writes a textured model with the features of the Khronos "Duck" sample (whose
/// licence does not allow carrying it): the root node's `matrix` scales by 0.01; a
/// perspective camera node with its own rotation + translation `matrix` is a child
/// of that root, so its world transform includes the scale; POSITION and NORMAL are
/// interleaved in one bufferView (`byteStride` 24), TEXCOORD_0 has a `byteStride` of
/// 8; u16 indices; a PNG base colour texture. As `name`.gltf (external .bin and
/// .png) and `name`.glb (buffer and image in the BIN chunk). Returns both paths.
std::pair<fs::path, fs::path> write_duck_like(const fs::path& dir, const std::string& name) {
    const TriangleMesh ico = make_icosphere(4, 100.0f, {10.0f, 90.0f, -5.0f});
    Blob blob;
    std::vector<uint8_t> inter(ico.positions.size() * 24);
    std::vector<float> uvs;
    Bounds3 box;
    for (size_t v = 0; v < ico.positions.size(); ++v) {
        const Vec3 p = ico.positions[v], n = normalize(p - Vec3(10.0f, 90.0f, -5.0f));
        std::memcpy(&inter[v * 24], &p, 12);
        std::memcpy(&inter[v * 24 + 12], &n, 12);
        uvs.insert(uvs.end(), {0.5f + 0.5f * n.x, 0.5f + 0.5f * n.y});
        box.extend(p);
    }
    std::vector<uint16_t> idx(ico.indices.begin(), ico.indices.end());
    const size_t inter_at = blob.add(inter), uv_at = blob.add(uvs), idx_at = blob.add(idx);
    const uint8_t px[16] = {250, 220, 0, 255, 255, 160, 0, 255, 240, 200, 10, 255, 255, 255, 255, 255};
    write_image_u8(dir / (name + ".png"), 2, 2, 4, px);
    const std::vector<uint8_t> png = read_all(dir / (name + ".png"));
    const size_t png_at = blob.add(png);

    // A camera at (400, 463, -431) looking at the origin, in the unscaled units of the mesh.
    const Vec3d eye(400.113, 463.264, -431.078);
    const Vec3d back = normalize(eye), right = normalize(cross(Vec3d(0, 1, 0), back)),
                up = cross(back, right);
    const json camera_matrix = {right.x, right.y, right.z, 0, up.x,  up.y,  up.z,  0,
                                back.x,  back.y,  back.z,  0, eye.x, eye.y, eye.z, 1};
    json j = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes",
         {{{"children", {2, 1}}, {"matrix", {0.01, 0, 0, 0, 0, 0.01, 0, 0, 0, 0, 0.01, 0, 0, 0, 0, 1}}},
          {{"matrix", camera_matrix}, {"camera", 0}},
          {{"mesh", 0}}}},
        {"cameras",
         {{{"type", "perspective"},
           {"perspective", {{"aspectRatio", 1.5}, {"yfov", 0.66}, {"znear", 1.0}, {"zfar", 10000.0}}}}}},
        {"meshes",
         {{{"primitives",
            {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
              {"indices", 3},
              {"material", 0},
              {"mode", 4}}}}}}},
        {"materials", {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
        {"textures", {{{"source", 0}}}},
        {"images", {{{"uri", name + ".png"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", inter_at}, {"byteLength", inter.size()}, {"byteStride", 24}},
          {{"buffer", 0}, {"byteOffset", uv_at}, {"byteLength", uvs.size() * 4}, {"byteStride", 8}},
          {{"buffer", 0}, {"byteOffset", idx_at}, {"byteLength", idx.size() * 2}},
          {{"buffer", 0}, {"byteOffset", png_at}, {"byteLength", png.size()}}}},
        {"accessors",
         {{{"bufferView", 0},
           {"componentType", 5126},
           {"type", "VEC3"},
           {"count", ico.positions.size()},
           {"min", {box.lo.x, box.lo.y, box.lo.z}},
           {"max", {box.hi.x, box.hi.y, box.hi.z}}},
          {{"bufferView", 0},
           {"byteOffset", 12},
           {"componentType", 5126},
           {"type", "VEC3"},
           {"count", ico.positions.size()}},
          {{"bufferView", 1}, {"componentType", 5126}, {"type", "VEC2"}, {"count", ico.positions.size()}},
          {{"bufferView", 2}, {"componentType", 5123}, {"type", "SCALAR"}, {"count", idx.size()}}}}};
    json external = j;
    external["buffers"] = {{{"byteLength", blob.bytes.size()}, {"uri", name + ".bin"}}};
    write_bytes(dir / (name + ".bin"), blob.bytes);
    write_text(dir / (name + ".gltf"), external.dump());
    json binary = j;
    binary["buffers"] = {{{"byteLength", blob.bytes.size()}}};
    binary["images"] = {{{"bufferView", 3}, {"mimeType", "image/png"}}};
    write_glb(dir / (name + ".glb"), binary, blob.bytes);
    return {dir / (name + ".gltf"), dir / (name + ".glb")};
}

/// Loads `file` and checks what its JSON says: the triangles the default scene draws,
/// no zero-area triangles, the materials and base colour textures its primitives use,
/// and the box of the accessors' min/max through the node transforms (exact when
/// `exact_box`: every rotation a multiple of 90 degrees; else a superset).
void check_gltf_loads(const fs::path& file, size_t scene_tris, bool exact_box) {
    CAPTURE(file.string());
    const json j = json_of(file);
    // Materials: those primitives name; textures: base colour textures they use, where
    // textures with the same image and sampler (CesiumMilkTruck has two) count once.
    std::set<int> mats;
    std::set<std::pair<int, int>> texs;
    for (const auto& mesh : j["meshes"])
        for (const auto& prim : mesh["primitives"]) mats.insert(prim.value("material", -1));
    for (int m : mats) {
        if (m < 0) continue;
        const json& mat = j["materials"][size_t(m)];
        if (mat.contains("pbrMetallicRoughness") &&
            mat["pbrMetallicRoughness"].contains("baseColorTexture")) {
            const json& tex =
                j["textures"][mat["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<size_t>()];
            texs.insert({tex.value("source", -1), tex.value("sampler", -1)});
        }
    }
    set_log_quiet(true);
    const LoadedModel m = load_model(file);
    set_log_quiet(false);
    CHECK(triangles(m) == scene_tris);
    CHECK(m.dropped_degenerate == 0);
    CHECK(m.materials.size() == mats.size());
    CHECK(m.textures.size() == texs.size());
    const Bounds3 got = bounds(m), want = corner_bounds(j);
    for (int k = 0; k < 3; ++k) {
        if (exact_box) {
            CHECK(got.lo[k] == doctest::Approx(want.lo[k]).epsilon(1e-4));
            CHECK(got.hi[k] == doctest::Approx(want.hi[k]).epsilon(1e-4));
        } else {
            CHECK(got.lo[k] >= want.lo[k] - 1e-4f);
            CHECK(got.hi[k] <= want.hi[k] + 1e-4f);
        }
    }
    for (const TextureDesc& t : m.textures) CHECK(t.image->width > 0);
}

}  // namespace

TEST_CASE("the glTF files in tests/data load with their published counts") {
    struct Expect {
        const char* path;
        size_t scene_tris;  // tests/data/SOURCES.md "scene tris"
        bool exact_box;     // all rotations multiples of 90 degrees
    };
    const Expect expect[] = {
        {"gltf/Box/glTF/Box.gltf", 12, true},
        {"gltf/Box/glTF-Binary/Box.glb", 12, true},
        {"gltf/Box/glTF-Embedded/Box.gltf", 12, true},
        {"gltf/BoxTextured/glTF/BoxTextured.gltf", 12, true},
        {"gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, true},
        {"gltf/BoxTextured/glTF-Embedded/BoxTextured.gltf", 12, true},
        {"gltf/SimpleMeshes/glTF/SimpleMeshes.gltf", 2, true},
        {"gltf/SimpleMeshes/glTF-Embedded/SimpleMeshes.gltf", 2, true},
        {"gltf/Cameras/glTF/Cameras.gltf", 2, false},
        {"gltf/Cameras/glTF-Embedded/Cameras.gltf", 2, false},
        {"gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf", 3624, false},
        {"gltf/CesiumMilkTruck/glTF-Binary/CesiumMilkTruck.glb", 3624, false},
        {"gltf/VivaBalloon/scene.gltf", 35698, true},
    };
    for (const Expect& e : expect) check_gltf_loads(kTestData / e.path, e.scene_tris, e.exact_box);
}

TEST_CASE(
    "a Duck-like glTF (scaled root / camera child / interleaved strides) loads whole / .gltf and .glb") {
    const auto [gltf, glb] = write_duck_like(scratch("duck_counts"), "duck");
    const size_t tris = make_icosphere(4).triangle_count();
    check_gltf_loads(gltf, tris, true);
    check_gltf_loads(glb, tris, true);
}

TEST_CASE("glTF cameras: a camera under a 0.01-scaled root includes the scale and Cameras has both kinds") {
    const fs::path duck_file = write_duck_like(scratch("duck_camera"), "duck").first;
    const LoadedModel duck = load_gltf(duck_file);
    REQUIRE(duck.cameras.size() == 1);
    const json j = json_of(duck_file);
    const auto& cm = j["nodes"][1]["matrix"];
    const CameraDesc& c = duck.cameras[0];
    CHECK(c.has_basis);
    CHECK(c.position.x == doctest::Approx(0.01 * cm[12].get<double>()));
    CHECK(c.position.y == doctest::Approx(0.01 * cm[13].get<double>()));
    CHECK(c.position.z == doctest::Approx(0.01 * cm[14].get<double>()));
    // Forward is the node's -Z column.
    CHECK(c.basis_forward.x == doctest::Approx(-cm[8].get<double>()).epsilon(1e-4));
    CHECK(c.basis_forward.z == doctest::Approx(-cm[10].get<double>()).epsilon(1e-4));
    CHECK(c.basis_up.y == doctest::Approx(cm[5].get<double>()).epsilon(1e-4));
    CHECK(c.vfov ==
          doctest::Approx(j["cameras"][0]["perspective"]["yfov"].get<double>() * 180 / std::numbers::pi));

    const LoadedModel cams = load_gltf(kTestData / "gltf/Cameras/glTF/Cameras.gltf");
    REQUIRE(cams.cameras.size() == 2);
    CHECK(!cams.cameras[0].orthographic);
    CHECK(cams.cameras[0].vfov == doctest::Approx(0.7 * 180 / std::numbers::pi));
    CHECK(cams.cameras[1].orthographic);
    CHECK(cams.cameras[1].ortho_height == doctest::Approx(2.0));
    CHECK(cams.cameras[1].position == Vec3(0.5f, 0.5f, 3.0f));
    CHECK(cams.cameras[1].basis_right == Vec3(1, 0, 0));
}

TEST_CASE("glTF node transforms: T * R * S / parents first / then world_from_model") {
    Doc d;
    const int mesh = d.mesh(d.positions({1, 0, 0, 0, 1, 0, 0, 0, 1}));
    const int child =
        d.node({{"mesh", mesh},
                {"translation", {0, 0, 5}},
                {"rotation", {0, 0, std::sin(std::numbers::pi / 4), std::cos(std::numbers::pi / 4)}},
                {"scale", {2, 2, 2}}},
               false);
    d.node({{"children", {child}}, {"translation", {10, 0, 0}}});
    const fs::path file = d.write(scratch("trs") / "trs.gltf");
    const LoadedModel m = load_gltf(file, Mat4::scale({1, 1, 3}));
    REQUIRE(m.meshes.size() == 1);
    // (1,0,0): scale 2 -> (2,0,0), rotate 90 deg about Z -> (0,2,0), +(0,0,5), +(10,0,0), z*3.
    const Vec3 p = m.meshes[0].positions[0];
    CHECK(p.x == doctest::Approx(10));
    CHECK(p.y == doctest::Approx(2));
    CHECK(p.z == doctest::Approx(15));
    const Vec3 q = m.meshes[0].positions[2];  // (0,0,1) -> (0,0,2) -> +5 -> 7 -> *3
    CHECK(q.z == doctest::Approx(21));
}

TEST_CASE("glTF instancing: a mesh used by three nodes appears three times") {
    Doc d;
    const int mesh = d.mesh(d.positions(kTriangle));
    for (int i = 0; i < 3; ++i) d.node({{"mesh", mesh}, {"translation", {i * 2, 0, 0}}});
    const LoadedModel m = load_gltf(d.write(scratch("inst") / "inst.gltf"));
    REQUIRE(m.meshes.size() == 3);
    CHECK(bounds(m).hi.x == doctest::Approx(5));
    CHECK(m.materials.size() == 1);  // the default material, shared
}

TEST_CASE("glTF mirroring transforms keep triangles front-facing") {
    Doc d;
    const int mesh =
        d.mesh(d.positions(kTriangle), -1, 4,
               {{"NORMAL", d.accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, 5126, "VEC3", 3)}});
    d.node({{"mesh", mesh}, {"scale", {-1, 1, 1}}});
    d.node({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
    const LoadedModel m = load_gltf(d.write(scratch("mirror") / "mirror.gltf"));
    REQUIRE(m.meshes.size() == 2);
    for (const TriangleMesh& mesh_i : m.meshes) {
        // The geometric normal agrees with the transformed shading normal (+Z stays +Z).
        CHECK(face_normal(mesh_i, 0).z == doctest::Approx(1));
        CHECK(mesh_i.normals[0].z == doctest::Approx(1));
    }
}

TEST_CASE("glTF triangle strips and fans become consistently wound lists") {
    Doc d;
    // A 2x1 strip of 4 vertices, zig-zag order, all facing +Z.
    const int strip = d.mesh(d.positions({0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0}), -1, 5);
    // A fan around the origin, counter-clockwise.
    std::vector<float> fan = {0, 0, 0};
    for (int k = 0; k <= 4; ++k) {
        const double a = k * std::numbers::pi / 4;
        fan.insert(fan.end(), {float(std::cos(a)), float(std::sin(a)), 0});
    }
    const int fan_mesh =
        d.mesh(d.positions(fan), d.accessor(std::vector<uint8_t>{0, 1, 2, 3, 4, 5}, 5121, "SCALAR", 6), 6);
    d.node({{"mesh", strip}});
    d.node({{"mesh", fan_mesh}});
    d.j["meshes"][0]["primitives"][0]["indices"] =
        d.accessor(std::vector<uint8_t>{1, 0, 3, 2, 5, 4}, 5121, "SCALAR", 6);
    const LoadedModel m = load_gltf(d.write(scratch("strip") / "strip.gltf"));
    REQUIRE(m.meshes.size() == 2);
    CHECK(m.meshes[0].triangle_count() == 4);
    CHECK(m.meshes[1].triangle_count() == 4);
    for (const auto& mesh : m.meshes)
        for (size_t t = 0; t < mesh.triangle_count(); ++t)
            CHECK(face_normal(mesh, t).z == doctest::Approx(1));
}

TEST_CASE("glTF sparse accessors are applied / with and without a base bufferView") {
    Doc d;
    const int pos = d.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5});
    const size_t idx_at = d.blob.add(std::vector<uint16_t>{3, 0});
    const size_t val_at = d.blob.add(std::vector<float>{1, 1, 0, 0, 0, 7});
    d.j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", idx_at}, {"byteLength", 4}});
    d.j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", val_at}, {"byteLength", 24}});
    const json sparse = {
        {"count", 2},
        {"indices", {{"bufferView", d.j["bufferViews"].size() - 2}, {"componentType", 5123}}},
        {"values", {{"bufferView", d.j["bufferViews"].size() - 1}}}};
    d.j["accessors"][size_t(pos)]["sparse"] = sparse;
    // A second accessor: no bufferView, zeros plus the same substitution.
    d.j["accessors"].push_back({{"componentType", 5126}, {"type", "VEC3"}, {"count", 4}, {"sparse", sparse}});
    const int zero_based = int(d.j["accessors"].size()) - 1;
    const int indices = d.accessor(std::vector<uint32_t>{0, 1, 3}, 5125, "SCALAR", 3);
    d.node({{"mesh", d.mesh(pos, indices)}});
    d.node({{"mesh", d.mesh(zero_based, indices)}});
    const LoadedModel m = load_gltf(d.write(scratch("sparse") / "sparse.gltf"));
    REQUIRE(m.meshes.size() == 2);
    CHECK(m.meshes[0].positions[0] == Vec3(0, 0, 7));
    CHECK(m.meshes[0].positions[3] == Vec3(1, 1, 0));
    CHECK(m.meshes[0].positions[1] == Vec3(1, 0, 0));
    CHECK(m.meshes[1].positions[1] == Vec3(0, 0, 0));
    CHECK(m.meshes[1].positions[3] == Vec3(1, 1, 0));
}

TEST_CASE("glTF buffers: external .bin / data URI and .glb give the same mesh") {
    const fs::path dir = scratch("containers");
    Doc d;
    const int pos = d.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
    // Interleaved: normal (3 floats) + uv (2 u16 normalized) per vertex, stride 16.
    std::vector<uint8_t> inter(4 * 16);
    for (int v = 0; v < 4; ++v) {
        const float n[3] = {0, 0, 1};
        const uint16_t uv[2] = {uint16_t(v & 1 ? 65535 : 0), uint16_t(v & 2 ? 65535 : 0)};
        std::memcpy(&inter[size_t(v) * 16], n, 12);
        std::memcpy(&inter[size_t(v) * 16 + 12], uv, 4);
    }
    const size_t at = d.blob.add(inter);
    d.j["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", at}, {"byteLength", inter.size()}, {"byteStride", 16}});
    const int view = int(d.j["bufferViews"].size()) - 1;
    d.j["accessors"].push_back(
        {{"bufferView", view}, {"componentType", 5126}, {"type", "VEC3"}, {"count", 4}});
    d.j["accessors"].push_back({{"bufferView", view},
                                {"byteOffset", 12},
                                {"componentType", 5123},
                                {"normalized", true},
                                {"type", "VEC2"},
                                {"count", 4}});
    const int nrm = int(d.j["accessors"].size()) - 2, uv = nrm + 1;
    d.node({{"mesh", d.mesh(pos, d.accessor(std::vector<uint16_t>{0, 1, 2, 2, 1, 3}, 5123, "SCALAR", 6), 4,
                            {{"NORMAL", nrm}, {"TEXCOORD_0", uv}})}});
    const LoadedModel embedded = load_gltf(d.write(dir / "embedded.gltf"));

    json ext = d.j;
    ext["buffers"] = {{{"byteLength", d.blob.bytes.size()}, {"uri", "my%20data.bin"}}};
    write_text(dir / "external.gltf", ext.dump());
    write_bytes(dir / "my data.bin", d.blob.bytes);
    const LoadedModel external = load_gltf(dir / "external.gltf");

    json glb = d.j;
    glb["buffers"] = {{{"byteLength", d.blob.bytes.size()}}};
    write_glb(dir / "binary.glb", glb, d.blob.bytes);
    const LoadedModel binary = load_model(dir / "binary.glb");

    for (const LoadedModel* m : {&embedded, &external, &binary}) {
        REQUIRE(m->meshes.size() == 1);
        const TriangleMesh& mesh = m->meshes[0];
        CHECK(mesh.positions == embedded.meshes[0].positions);
        CHECK(mesh.indices == std::vector<uint32_t>{0, 1, 2, 2, 1, 3});
        REQUIRE(mesh.uvs.size() == 4);
        CHECK(mesh.normals[3] == Vec3(0, 0, 1));
        // glTF v (down) becomes sahara v (up): vertex 3 has v_gltf = 1 -> v = 0.
        CHECK(mesh.uvs[3].x == 1.0f);
        CHECK(mesh.uvs[3].y == 0.0f);
        CHECK(mesh.uvs[0].y == 1.0f);
    }
}

TEST_CASE("KHR_lights_punctual lights and glTF cameras under a scaled parent") {
    Doc d;
    d.j["extensionsUsed"] = {"KHR_lights_punctual"};
    d.j["extensions"] = {{"KHR_lights_punctual",
                          {{"lights",
                            {{{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 8}},
                             {{"type", "directional"}, {"intensity", 3}},
                             {{"type", "spot"}, {"intensity", 2}, {"spot", {{"outerConeAngle", 0.5}}}}}}}}};
    d.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}},
                      {{"type", "orthographic"},
                       {"orthographic", {{"xmag", 2}, {"ymag", 1.5}, {"znear", 0.1}, {"zfar", 10}}}}};
    auto light = [](int i) { return json{{"KHR_lights_punctual", {{"light", i}}}}; };
    const int c0 = d.node({{"translation", {0, 0, 10}}, {"extensions", light(0)}}, false);
    // Rotated -90 degrees about X: local -Z points to world -Y.
    const double h = std::sqrt(0.5);
    const int c1 = d.node({{"rotation", {-h, 0, 0, h}}, {"extensions", light(1)}}, false);
    const int c2 = d.node({{"translation", {1, 0, 0}}, {"extensions", light(2)}, {"camera", 0}}, false);
    const int c3 = d.node({{"translation", {0, 0, 4}}, {"camera", 1}}, false);
    d.node({{"scale", {2, 2, 2}}, {"children", {c0, c1, c2, c3}}});
    const LoadedModel m = load_gltf(d.write(scratch("lights") / "lights.gltf"));
    REQUIRE(m.lights.size() == 3);
    const auto point =
        std::find_if(m.lights.begin(), m.lights.end(), [](auto& l) { return l.intensity.x == 8.0f; });
    REQUIRE(point != m.lights.end());
    CHECK(point->type == LightDesc::Type::point);
    CHECK(point->position == Vec3(0, 0, 20));
    CHECK(point->intensity == Rgb(8, 4, 2));
    const auto spot =
        std::find_if(m.lights.begin(), m.lights.end(), [](auto& l) { return l.intensity.x == 2.0f; });
    REQUIRE(spot != m.lights.end());
    CHECK(spot->type == LightDesc::Type::point);
    CHECK(spot->position == Vec3(2, 0, 0));
    const auto dir_it = std::find_if(m.lights.begin(), m.lights.end(),
                                     [](auto& l) { return l.type == LightDesc::Type::directional; });
    REQUIRE(dir_it != m.lights.end());
    CHECK(dir_it->irradiance == Rgb(3, 3, 3));
    CHECK(dir_it->direction.y == doctest::Approx(-1));
    REQUIRE(m.cameras.size() == 2);
    const auto persp =
        std::find_if(m.cameras.begin(), m.cameras.end(), [](auto& c) { return !c.orthographic; });
    const auto ortho =
        std::find_if(m.cameras.begin(), m.cameras.end(), [](auto& c) { return c.orthographic; });
    CHECK(persp->position == Vec3(2, 0, 0));
    CHECK(persp->vfov == doctest::Approx(0.5 * 180 / std::numbers::pi));
    CHECK(persp->basis_forward == Vec3(0, 0, -1));
    CHECK(ortho->position == Vec3(0, 0, 8));
    CHECK(ortho->ortho_height == doctest::Approx(2 * 1.5 * 2));  // ymag, times the parent's scale
}

TEST_CASE("glTF primitives of points and lines are skipped with a warning") {
    Doc d;
    d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 1)}});
    d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 4)}});
    const int before = warning_count();
    const LoadedModel m = load_gltf(d.write(scratch("lines") / "lines.gltf"));
    CHECK(warning_count() == before + 1);
    CHECK(m.meshes.size() == 1);
}
