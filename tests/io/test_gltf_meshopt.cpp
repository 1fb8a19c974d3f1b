// EXT_meshopt_compression: files whose bufferViews are encoded here with
// meshoptimizer's own encoders (and filters) load like their uncompressed
// source; the fallback buffer without uri is no error; corrupt data is an
// InputError naming the bufferView.
#include <meshoptimizer.h>

#include "gltf_grid_mesh.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

const char* kExt = "EXT_meshopt_compression";

/// A glTF document whose bufferViews decode from buffer 0 (compressed) into
/// buffer 1 (the fallback: no uri).
struct MeshoptDoc {
    Doc d;
    size_t fallback_size = 0;

    /// Adds a compressed bufferView of `count` x `stride` bytes and an accessor over it.
    int accessor(const std::vector<uint8_t>& compressed, size_t count, size_t stride, const char* mode,
                 const char* filter, int component_type, const char* type, bool normalized = false) {
        const size_t at = d.blob.add(compressed);
        json view = {{"buffer", 1}, {"byteOffset", fallback_size}, {"byteLength", count * stride}};
        if (std::string(mode) == "ATTRIBUTES") view["byteStride"] = stride;
        view["extensions"][kExt] = {
            {"buffer", 0},          {"byteOffset", at}, {"byteLength", compressed.size()},
            {"byteStride", stride}, {"count", count},   {"mode", mode},
            {"filter", filter}};
        fallback_size += (count * stride + 3) / 4 * 4;
        d.j["bufferViews"].push_back(view);
        json a = {{"bufferView", d.j["bufferViews"].size() - 1},
                  {"componentType", component_type},
                  {"type", type},
                  {"count", count}};
        if (normalized) a["normalized"] = true;
        d.j["accessors"].push_back(a);
        return int(d.j["accessors"].size()) - 1;
    }
    json buffers(bool glb) const {
        json compressed = {{"byteLength", d.blob.bytes.size()}};
        if (!glb) compressed["uri"] = d.blob.data_uri();
        json fallback = {{"byteLength", fallback_size}};
        fallback["extensions"][kExt] = {{"fallback", true}};
        return {compressed, fallback};
    }
    fs::path write(const fs::path& file) {
        json j = d.j;
        j["buffers"] = buffers(false);
        write_text(file, j.dump());
        return file;
    }
    fs::path write_glb(const fs::path& file) {
        json j = d.j;
        j["buffers"] = buffers(true);
        test::gltf::write_glb(file, j, d.blob.bytes);
        return file;
    }
};

template <class T>
std::vector<uint8_t> encode_vertices(const std::vector<T>& data, size_t stride) {
    const size_t count = data.size() * sizeof(T) / stride;
    std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data.data(), count, stride));
    return out;
}

std::vector<uint8_t> encode_triangles(const std::vector<uint32_t>& idx, size_t vertices) {
    std::vector<uint8_t> out(meshopt_encodeIndexBufferBound(idx.size(), vertices));
    out.resize(meshopt_encodeIndexBuffer(out.data(), out.size(), idx.data(), idx.size()));
    return out;
}

/// `g` with its triangles as meshopt's index codec returns them: each triangle
/// may be rotated (same corners, same winding), so corners compare in that order.
GridMesh as_index_codec_returns(GridMesh g) {
    const std::vector<uint8_t> bytes = encode_triangles(g.indices, g.vertices());
    REQUIRE(meshopt_decodeIndexBuffer(g.indices.data(), g.indices.size(), 4, bytes.data(), bytes.size()) ==
            0);
    return g;
}

/// The grid with positions and uvs unfiltered, normals octahedral (8 bits),
/// indices as TRIANGLES (u32) or as an INDICES sequence (u16).
MeshoptDoc meshopt_grid(const GridMesh& g, bool triangles_mode) {
    MeshoptDoc m;
    m.d.j["extensionsUsed"] = {kExt, "KHR_mesh_quantization"};
    m.d.j["extensionsRequired"] = {kExt, "KHR_mesh_quantization"};
    const size_t n = g.vertices();
    const int pos = m.accessor(encode_vertices(g.positions, 12), n, 12, "ATTRIBUTES", "NONE", 5126, "VEC3");
    std::vector<float> n4;
    for (size_t i = 0; i < n; ++i)
        n4.insert(n4.end(), {g.normals[3 * i], g.normals[3 * i + 1], g.normals[3 * i + 2], 0});
    std::vector<int8_t> oct(4 * n);
    meshopt_encodeFilterOct(oct.data(), n, 4, 8, n4.data());
    const int nrm = m.accessor(encode_vertices(oct, 4), n, 4, "ATTRIBUTES", "OCTAHEDRAL", 5120, "VEC3", true);
    const int uv = m.accessor(encode_vertices(g.uvs, 8), n, 8, "ATTRIBUTES", "NONE", 5126, "VEC2");
    int idx = -1;
    if (triangles_mode) {
        idx = m.accessor(encode_triangles(g.indices, n), g.indices.size(), 4, "TRIANGLES", "NONE", 5125,
                         "SCALAR");
    } else {
        std::vector<uint8_t> seq(meshopt_encodeIndexSequenceBound(g.indices.size(), n));
        seq.resize(meshopt_encodeIndexSequence(seq.data(), seq.size(), g.indices.data(), g.indices.size()));
        idx = m.accessor(seq, g.indices.size(), 2, "INDICES", "NONE", 5123, "SCALAR");
    }
    m.d.node({{"mesh", m.d.mesh(pos, idx, 4, {{"NORMAL", nrm}, {"TEXCOORD_0", uv}})}});
    return m;
}

}  // namespace

TEST_CASE("glTF EXT_meshopt_compression loads like the uncompressed mesh (.gltf and .glb)") {
    const fs::path dir = scratch("meshopt");
    const GridMesh g = grid_mesh();
    for (bool triangles_mode : {true, false}) {
        CAPTURE(triangles_mode);
        const GridMesh want = triangles_mode ? as_index_codec_returns(g) : g;
        const LoadedModel plain = load_gltf(plain_grid_doc(want).write(dir / "plain.gltf"));
        MeshoptDoc m = meshopt_grid(g, triangles_mode);
        // Unfiltered data is exact; 8-bit octahedral normals are within about 1/127.
        check_same_corners(load_gltf(m.write(dir / "m.gltf")).meshes.at(0), plain.meshes[0], 0.0f, 0.02f,
                           0.0f);
        check_same_corners(load_gltf(m.write_glb(dir / "m.glb")).meshes.at(0), plain.meshes[0], 0.0f, 0.02f,
                           0.0f);
    }
}

TEST_CASE("glTF EXT_meshopt_compression EXPONENTIAL filter") {
    const fs::path dir = scratch("meshopt_exp");
    const GridMesh g = grid_mesh();
    MeshoptDoc m = meshopt_grid(g, true);
    std::vector<uint32_t> exp(g.positions.size());
    meshopt_encodeFilterExp(exp.data(), g.vertices(), 12, 20, g.positions.data());
    // POSITION again, now with 20-bit mantissas through the exponential filter.
    m.accessor(encode_vertices(exp, 12), g.vertices(), 12, "ATTRIBUTES", "EXPONENTIAL", 5126, "VEC3");
    m.d.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = m.d.j["accessors"].size() - 1;
    const LoadedModel plain = load_gltf(plain_grid_doc(as_index_codec_returns(g)).write(dir / "plain.gltf"));
    check_same_corners(load_gltf(m.write(dir / "exp.gltf")).meshes.at(0), plain.meshes[0], 1e-5f, 0.02f,
                       0.0f);
}

TEST_CASE("glTF EXT_meshopt_compression corrupt data is an InputError naming the bufferView") {
    const fs::path dir = scratch("meshopt_corrupt");
    const GridMesh g = grid_mesh();
    MeshoptDoc m = meshopt_grid(g, true);
    json& ext = m.d.j["bufferViews"][0]["extensions"][kExt];
    const size_t length = ext["byteLength"];
    ext["byteLength"] = length / 2;
    CHECK(error_of([&] {
              load_gltf(m.write(dir / "half.gltf"));
          }).find("bufferViews[0].extensions." + std::string(kExt)) != std::string::npos);
    ext["byteLength"] = length;
    ext["mode"] = "SPIRAL";
    CHECK(error_of([&] { load_gltf(m.write(dir / "mode.gltf")); }).find("mode must be") != std::string::npos);
    ext["mode"] = "ATTRIBUTES";
    ext["count"] = 1u << 30;  // a few bytes cannot hold 12 GB
    CHECK(error_of([&] { load_gltf(m.write(dir / "count.gltf")); }).find("bufferViews[0]") !=
          std::string::npos);
    // Every single flipped byte of the index data: an InputError or a mesh, never a crash.
    MeshoptDoc good = meshopt_grid(g, true);
    const json idx_ext = good.d.j["bufferViews"][3]["extensions"][kExt];
    const size_t at = idx_ext["byteOffset"], size = idx_ext["byteLength"];
    size_t refused = 0;
    for (size_t i = at; i < at + size; ++i) {
        MeshoptDoc flipped = good;
        flipped.d.blob.bytes[i] ^= 0xFF;
        try {
            load_gltf(flipped.write(dir / "flip.gltf"));
        } catch (const InputError&) {
            ++refused;
        }
    }
    CHECK(refused > 0);
}

TEST_CASE("glTF EXT_meshopt_compression carries EXT_mesh_gpu_instancing rotations (QUATERNION filter)") {
    const fs::path dir = scratch("meshopt_instancing");
    const float h = std::sqrt(0.5f);
    const std::vector<float> quats = {0, 0, h, h, 0.5f, 0.5f, 0.5f, 0.5f, 0, 1, 0, 0};
    std::vector<int16_t> packed(quats.size());
    meshopt_encodeFilterQuat(packed.data(), 3, 8, 16, quats.data());
    const std::vector<float> moves = {0, 0, 0, 3, 0, 0, 0, 3, 0};
    MeshoptDoc m;
    m.d.j["extensionsRequired"] = {kExt, "EXT_mesh_gpu_instancing"};
    const int rot =
        m.accessor(encode_vertices(packed, 8), 3, 8, "ATTRIBUTES", "QUATERNION", 5122, "VEC4", true);
    const int move = m.accessor(encode_vertices(moves, 12), 3, 12, "ATTRIBUTES", "NONE", 5126, "VEC3");
    const int pos = m.accessor(encode_vertices(kTriangle, 12), 3, 12, "ATTRIBUTES", "NONE", 5126, "VEC3");
    m.d.node({{"mesh", m.d.mesh(pos)},
              {"extensions",
               {{"EXT_mesh_gpu_instancing", {{"attributes", {{"ROTATION", rot}, {"TRANSLATION", move}}}}}}}});
    const LoadedModel model = load_gltf(m.write(dir / "instanced.gltf"));
    REQUIRE(model.instances.size() == 3);
    for (size_t k = 0; k < 3; ++k) {
        const Mat4 want =
            Mat4::translate({moves[3 * k], moves[3 * k + 1], moves[3 * k + 2]}) *
            Mat4::rotate_quaternion(quats[4 * k], quats[4 * k + 1], quats[4 * k + 2], quats[4 * k + 3]);
        for (size_t r = 0; r < 3; ++r)
            for (size_t c = 0; c < 4; ++c)
                CHECK(model.instances[k].world_from_object.m[r][c] ==
                      doctest::Approx(want.m[r][c]).epsilon(1e-3));
    }
}
