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
#include "mesh_fixtures.h"
#include "scene/texture.h"
#include "test_data.h"

using namespace sahara;
using sahara::test::kTestData;
using sahara::test::make_icosphere;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

fs::path scratch(const std::string& name) {
    fs::path dir = fs::temp_directory_path() / ("sahara_gltf_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::vector<uint8_t> read_all(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& f, const std::vector<uint8_t>& b) {
    std::ofstream(f, std::ios::binary)
        .write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

void write_text(const fs::path& f, const std::string& s) { std::ofstream(f, std::ios::binary) << s; }

std::string base64(const std::vector<uint8_t>& in) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < in.size(); i += 3) {
        uint32_t v = uint32_t(in[i]) << 16;
        if (i + 1 < in.size()) v |= uint32_t(in[i + 1]) << 8;
        if (i + 2 < in.size()) v |= in[i + 2];
        out += t[v >> 18 & 63];
        out += t[v >> 12 & 63];
        out += i + 1 < in.size() ? t[v >> 6 & 63] : '=';
        out += i + 2 < in.size() ? t[v & 63] : '=';
    }
    return out;
}

/// A binary buffer assembled by the tests, 4-byte aligned per block.
struct Blob {
    std::vector<uint8_t> bytes;
    template <class T>
    size_t add(const std::vector<T>& values) {
        while (bytes.size() % 4) bytes.push_back(0);
        const size_t at = bytes.size();
        bytes.resize(at + values.size() * sizeof(T));
        std::memcpy(bytes.data() + at, values.data(), values.size() * sizeof(T));
        return at;
    }
    std::string data_uri() const { return "data:application/octet-stream;base64," + base64(bytes); }
};

/// A glTF document built in the tests: one buffer (embedded as a data URI by default).
struct Doc {
    json j = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", json::array()}}}},
              {"nodes", json::array()},
              {"meshes", json::array()},
              {"accessors", json::array()},
              {"bufferViews", json::array()},
              {"buffers", json::array()}};
    Blob blob;

    /// Adds data as its own bufferView and an accessor over it.
    template <class T>
    int accessor(const std::vector<T>& data, int component_type, const char* type, size_t count,
                 bool normalized = false) {
        const size_t at = blob.add(data);
        j["bufferViews"].push_back(
            {{"buffer", 0}, {"byteOffset", at}, {"byteLength", data.size() * sizeof(T)}});
        json a = {{"bufferView", j["bufferViews"].size() - 1},
                  {"componentType", component_type},
                  {"type", type},
                  {"count", count}};
        if (normalized) a["normalized"] = true;
        j["accessors"].push_back(a);
        return int(j["accessors"].size()) - 1;
    }
    int positions(const std::vector<float>& p) { return accessor(p, 5126, "VEC3", p.size() / 3); }
    int mesh(int pos, int indices = -1, int mode = 4, json extra_attrs = json::object()) {
        json prim = {{"attributes", {{"POSITION", pos}}}, {"mode", mode}};
        for (auto& [k, v] : extra_attrs.items()) prim["attributes"][k] = v;
        if (indices >= 0) prim["indices"] = indices;
        j["meshes"].push_back({{"primitives", {prim}}});
        return int(j["meshes"].size()) - 1;
    }
    int node(json n, bool root = true) {
        j["nodes"].push_back(n);
        const int i = int(j["nodes"].size()) - 1;
        if (root) j["scenes"][0]["nodes"].push_back(i);
        return i;
    }
    std::string text() {
        j["buffers"] = json::array();
        if (!blob.bytes.empty())
            j["buffers"].push_back({{"byteLength", blob.bytes.size()}, {"uri", blob.data_uri()}});
        return j.dump();
    }
    fs::path write(const fs::path& file) {
        write_text(file, text());
        return file;
    }
};

/// Writes a .glb holding `j` with the BIN chunk `bin`.
void write_glb(const fs::path& file, json j, std::vector<uint8_t> bin) {
    std::string text = j.dump();
    while (text.size() % 4) text += ' ';
    while (bin.size() % 4) bin.push_back(0);
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) {
        for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    u32(uint32_t(text.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    u32(uint32_t(bin.size()));
    u32(0x004E4942);
    out.insert(out.end(), bin.begin(), bin.end());
    write_bytes(file, out);
}

/// The JSON of a .gltf or .glb file, parsed in the test itself.
json json_of(const fs::path& file) {
    const std::vector<uint8_t> b = read_all(file);
    if (b.size() >= 20 && std::memcmp(b.data(), "glTF", 4) == 0) {
        uint32_t len;
        std::memcpy(&len, &b[12], 4);
        return json::parse(b.begin() + 20, b.begin() + 20 + len);
    }
    return json::parse(b);
}

size_t triangles(const LoadedModel& m) {
    size_t n = 0;
    for (const auto& mesh : m.meshes) n += mesh.triangle_count();
    return n;
}

Bounds3 bounds(const LoadedModel& m) {
    Bounds3 b;
    for (const auto& mesh : m.meshes) b.extend(mesh_bounds(mesh));
    return b;
}

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

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

Vec3 face_normal(const TriangleMesh& m, size_t t) {
    const auto& p = m.positions;
    const uint32_t* i = &m.indices[3 * t];
    return triangle_normal(p[i[0]], p[i[1]], p[i[2]]);
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

TEST_CASE("a Duck-like glTF (scaled root, camera child, interleaved strides) loads whole, .gltf and .glb") {
    const auto [gltf, glb] = write_duck_like(scratch("duck_counts"), "duck");
    const size_t tris = make_icosphere(4).triangle_count();
    check_gltf_loads(gltf, tris, true);
    check_gltf_loads(glb, tris, true);
}

TEST_CASE("glTF cameras: a camera under a 0.01-scaled root includes the scale, and Cameras has both kinds") {
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

TEST_CASE("glTF node transforms: T * R * S, parents first, then world_from_model") {
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

TEST_CASE("glTF sparse accessors are applied, with and without a base bufferView") {
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

TEST_CASE("glTF buffers: external .bin, data URI and .glb give the same mesh") {
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

namespace {

/// A 2x2 RGBA PNG (written through OpenImageIO): top row red, (0,128,0,128); bottom row blue, white.
std::vector<uint8_t> tiny_png(const fs::path& dir) {
    const uint8_t px[16] = {255, 0, 0, 255, 0, 128, 0, 128, 0, 0, 255, 255, 255, 255, 255, 255};
    const fs::path file = dir / "tiny.png";
    write_image_u8(file, 2, 2, 4, px);
    return read_all(file);
}

/// A one-triangle document whose primitive uses material 0, with uvs.
Doc textured_doc(const json& material) {
    Doc d;
    const int uv = d.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, 5126, "VEC2", 3);
    d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 4, {{"TEXCOORD_0", uv}})}});
    d.j["meshes"][0]["primitives"][0]["material"] = 0;
    d.j["materials"] = {material};
    return d;
}

/// A PNG assembled chunk by chunk (valid CRCs): RGBA8 `w` x `h`, IDAT bytes as given.
std::vector<uint8_t> handmade_png(uint32_t w, uint32_t h, const std::vector<uint8_t>& idat) {
    std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 13, 10, 26, 10};
    auto chunk = [&](const char* type, std::vector<uint8_t> data) {
        for (int k = 3; k >= 0; --k) png.push_back(uint8_t(data.size() >> (8 * k)));
        data.insert(data.begin(), type, type + 4);
        uint32_t crc = 0xFFFFFFFFu;  // CRC-32 of type + data, as PNG requires
        for (uint8_t b : data) {
            crc ^= b;
            for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
        crc = ~crc;
        png.insert(png.end(), data.begin(), data.end());
        for (int k = 3; k >= 0; --k) png.push_back(uint8_t(crc >> (8 * k)));
    };
    std::vector<uint8_t> ihdr;
    for (uint32_t v : {w, h})
        for (int k = 3; k >= 0; --k) ihdr.push_back(uint8_t(v >> (8 * k)));
    ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});
    chunk("IHDR", ihdr);
    chunk("IDAT", idat);
    chunk("IEND", {});
    return png;
}

}  // namespace

TEST_CASE("glTF materials: base colour factor x texture, alpha modes, emission, sRGB decoding") {
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
    CHECK(mat.type == MaterialType::emissive);
    CHECK(mat.radiance.color == Rgb(4, 2, 0));
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
    CHECK(mv.materials[0].type == MaterialType::lambertian);
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
        // glTF: t = offset + R * (scale * uv) with the spec's column-major GLSL
        // mat3(cos, sin, 0, -sin, cos, 0, ...), i.e. R = [cos -sin; sin cos]; row = t.y * height.
        const float su = scl[0] * u, sv = scl[1] * vg;
        const float tu = off[0] + std::cos(rot) * su - std::sin(rot) * sv;
        const float tv = off[1] + std::sin(rot) * su + std::cos(rot) * sv;
        // sahara (scene_desc.h, scene/texture.cpp): uv = (u, 1 - vg);
        // uv' = offset + [cos sin; -sin cos] * (scale * uv); row = (1 - uv'.y) * height.
        const float xu = t.uv_scale.x * u, xv = t.uv_scale.y * (1 - vg);
        const float pu = t.uv_offset.x + std::cos(t.uv_rotation) * xu + std::sin(t.uv_rotation) * xv;
        const float pv = t.uv_offset.y - std::sin(t.uv_rotation) * xu + std::cos(t.uv_rotation) * xv;
        CHECK(pu == doctest::Approx(tu).epsilon(1e-5));
        CHECK(1 - pv == doctest::Approx(tv).epsilon(1e-5));
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

TEST_CASE("bad glTF input throws InputError naming file and element") {
    const fs::path dir = scratch("bad");
    const std::string f = (dir / "x.gltf").string();
    auto load = [&](Doc& d) { return error_of([&] { load_gltf(d.write(dir / "x.gltf")); }); };
    CHECK(error_of([&] { load_gltf(dir / "none.gltf"); }) == (dir / "none.gltf").string() + ": no such file");
    fs::create_directories(dir / "folder.glb");
    CHECK(error_of([&] { load_model(dir / "folder.glb"); }).find("not a regular file") != std::string::npos);
    write_text(dir / "broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [");
    CHECK(error_of([&] { load_gltf(dir / "broken.gltf"); }).find("broken.gltf: malformed glTF") !=
          std::string::npos);

    {  // index out of range
        Doc d;
        d.node({{"mesh", d.mesh(d.positions(kTriangle),
                                d.accessor(std::vector<uint16_t>{0, 1, 3}, 5123, "SCALAR", 3))}});
        CHECK(load(d) == f + ": meshes[0].primitives[0].indices: index 3 out of range (3 vertices)");
    }
    {  // NaN coordinate
        Doc d;
        d.node({{"mesh", d.mesh(d.positions({0, 0, 0, 1, std::nanf(""), 0, 0, 1, 0}))}});
        CHECK(load(d) == f + ": accessors[0]: element 1 is not a finite number");
    }
    {  // accessor reading past its bufferView
        Doc d;
        const int pos = d.positions(kTriangle);
        d.j["accessors"][size_t(pos)]["count"] = 4;
        d.node({{"mesh", d.mesh(pos)}});
        CHECK(load(d) == f + ": accessors[0]: reads past the end of bufferViews[0]");
    }
    {  // bufferView past its buffer
        Doc d;
        const int pos = d.positions(kTriangle);
        d.j["bufferViews"][0]["byteLength"] = 400;
        d.node({{"mesh", d.mesh(pos)}});
        CHECK(load(d) == f + ": bufferViews[0]: extends past the end of buffers[0]");
    }
    {  // buffer larger than its file
        Doc d;
        d.node({{"mesh", d.mesh(d.positions(kTriangle))}});
        json j = d.j;
        j["buffers"] = {{{"byteLength", 1000}, {"uri", "small.bin"}}};
        write_bytes(dir / "small.bin", d.blob.bytes);
        write_text(dir / "big.gltf", j.dump());
        CHECK(error_of([&] { load_gltf(dir / "big.gltf"); }) ==
              (dir / "big.gltf").string() +
                  ": buffers[0]: byteLength 1000 is larger than small.bin (36 bytes)");
        j["buffers"] = {{{"byteLength", 1000}}};
        write_glb(dir / "big.glb", j, d.blob.bytes);
        CHECK(error_of([&] { load_gltf(dir / "big.glb"); }) ==
              (dir / "big.glb").string() +
                  ": buffers[0]: byteLength 1000 is larger than the GLB BIN chunk (36 bytes)");
    }
    {  // unsupported required extension
        Doc d;
        d.j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
        d.j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
        CHECK(load(d) == f + ": extensionsRequired: KHR_draco_mesh_compression is not supported");
    }
    {  // texture that fails to decode
        Doc d = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
        d.j["images"] = {
            {{"uri", "data:image/png;base64," + base64({0x89, 'P', 'N', 'G', 13, 10, 26, 10, 1, 2, 3})}}};
        d.j["textures"] = {{{"source", 0}}};
        CHECK(load(d) == f + ": images[0]: cannot decode image: PNG is truncated (chunk 0 header)");
        // Well-formed chunks around a corrupt zlib stream: the decoder itself fails.
        const std::vector<uint8_t> bad = handmade_png(4, 4, {0x78, 0x9C, 0xFF, 0xFF, 0xFF, 0x00, 0x11});
        d.j["images"] = {{{"uri", "data:image/png;base64," + base64(bad)}}};
        CHECK(load(d).find(f + ": images[0]: cannot decode image: ") == 0);
    }
    {  // an image over 32k pixels per side (a valid PNG header claiming 40000 x 8)
        // A well-formed PNG header claiming 40000 x 8 pixels.
        const std::vector<uint8_t> png =
            handmade_png(40000, 8, {0x78, 0x9C, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01});
        Doc d = textured_doc({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
        write_bytes(dir / "huge.png", png);
        d.j["images"] = {{{"uri", "huge.png"}}};
        d.j["textures"] = {{{"source", 0}}};
        const std::string e = load(d);
        CHECK(e.find(f + ": images[0]: ") == 0);
        CHECK(e.find("huge.png") != std::string::npos);
        CHECK(e.find("32768") != std::string::npos);
    }
    {  // node cycle
        Doc d;
        d.node({{"children", {1}}});
        d.node({{"children", {0}}}, false);
        CHECK(load(d) == f + ": nodes[0]: reached twice (cycle or shared child in the node tree)");
    }
    {  // references to things that do not exist
        Doc d;
        d.node({{"mesh", 5}});
        CHECK(load(d) == f + ": nodes[0].mesh: mesh 5 does not exist");
        Doc e;
        e.node({{"mesh", e.mesh(7)}});
        CHECK(load(e) == f + ": meshes[0].primitives[0].attributes.POSITION: accessor 7 does not exist");
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
    for (const json& ktt :
         {json(nullptr), json{{"offset", {0.5, 0}}}, json{{"rotation", std::numbers::pi / 2}}}) {
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
        } else if (ktt.contains("offset")) {
            CHECK(near(sample(m, 0), green));  // u + 0.5
        } else {
            // glTF rotation pi/2: t = [cos -sin; sin cos] p = (-0.25, 0.25) -> wraps to (0.75, 0.25): top
            // right.
            CHECK(near(sample(m, 0), green));
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

TEST_CASE("glTF: the material's TEXCOORD set, normalized byte normals, u8 and u32 indices") {
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
    CHECK(mesh.uvs[1].x == doctest::Approx(0.2f));  // 51/255 from TEXCOORD_1 (TEXCOORD_0 has 1 there)
    CHECK(mesh.uvs[2].y == 0.0f);                   // v_gltf = 1 -> 0
    CHECK(mesh.uvs[1].y == 1.0f);                   // v_gltf = 0 -> 1
    CHECK(mesh.normals[2] == Vec3(0, -1, 0));
    CHECK(mesh.indices == std::vector<uint32_t>{2, 1, 0});
}
