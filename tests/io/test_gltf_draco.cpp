// KHR_draco_mesh_compression: files whose meshes are encoded here with Draco's
// own encoder load like their uncompressed source, and corrupt bitstreams are
// refused with an InputError naming the primitive.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include "gltf_grid_mesh.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

const char* kElement = "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression";

/// `g` as a Draco bitstream: positions 14 bits, normals 10, uvs 12; sequential
/// connectivity keeps the face order (edgebreaker reorders faces).
std::vector<uint8_t> draco_bytes(const GridMesh& g, bool sequential = true) {
    draco::TriangleSoupMeshBuilder b;
    const int faces = int(g.indices.size() / 3);
    b.Start(faces);
    const int pos = b.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
    const int nrm = b.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
    const int uv = b.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
    for (int f = 0; f < faces; ++f) {
        const uint32_t* i = &g.indices[3 * size_t(f)];
        b.SetAttributeValuesForFace(pos, draco::FaceIndex(f), &g.positions[3 * i[0]], &g.positions[3 * i[1]],
                                    &g.positions[3 * i[2]]);
        b.SetAttributeValuesForFace(nrm, draco::FaceIndex(f), &g.normals[3 * i[0]], &g.normals[3 * i[1]],
                                    &g.normals[3 * i[2]]);
        b.SetAttributeValuesForFace(uv, draco::FaceIndex(f), &g.uvs[2 * i[0]], &g.uvs[2 * i[1]],
                                    &g.uvs[2 * i[2]]);
    }
    const std::unique_ptr<draco::Mesh> mesh = b.Finalize();
    REQUIRE(mesh != nullptr);
    // Attribute ids as the extension names them: POSITION 0, NORMAL 1, TEXCOORD_0 2.
    REQUIRE(mesh->attribute(pos)->unique_id() == 0);
    REQUIRE(mesh->attribute(uv)->unique_id() == 2);
    draco::Encoder enc;
    enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
    enc.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 10);
    enc.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 12);
    if (sequential) enc.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
    draco::EncoderBuffer out;
    REQUIRE(enc.EncodeMeshToBuffer(*mesh, &out).ok());
    return {out.data(), out.data() + out.size()};
}

/// Points and faces of a bitstream, for the accessor counts (as an exporter writes them).
std::pair<size_t, size_t> decoded_counts(const std::vector<uint8_t>& bytes) {
    draco::DecoderBuffer in;
    in.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder dec;
    auto mesh = dec.DecodeMeshFromBuffer(&in);
    REQUIRE(mesh.ok());
    return {mesh.value()->num_points(), mesh.value()->num_faces()};
}

json compressed_accessor(int type, const char* shape, size_t count) {
    return {{"componentType", type}, {"type", shape}, {"count", count}};
}

/// A one-primitive document whose data is only the bitstream `bytes` (counts from `source`).
Doc draco_doc(const std::vector<uint8_t>& bytes, const std::vector<uint8_t>& source) {
    const auto [points, faces] = decoded_counts(source);
    Doc d;
    d.j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    d.j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    const size_t at = d.blob.add(bytes);
    d.j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", bytes.size()}});
    for (const json& a :
         {compressed_accessor(5126, "VEC3", points), compressed_accessor(5126, "VEC3", points),
          compressed_accessor(5126, "VEC2", points), compressed_accessor(5123, "SCALAR", 3 * faces)})
        d.j["accessors"].push_back(a);
    d.node({{"mesh", d.mesh(0, 3, 4, {{"NORMAL", 1}, {"TEXCOORD_0", 2}})}});
    d.j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"] = {
        {"bufferView", 0}, {"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}};
    return d;
}

}  // namespace

TEST_CASE("glTF KHR_draco_mesh_compression loads like the uncompressed mesh (.gltf and .glb)") {
    const fs::path dir = scratch("draco");
    const GridMesh g = grid_mesh();
    const LoadedModel plain = load_gltf(plain_grid_doc(g).write(dir / "plain.gltf"));
    const std::vector<uint8_t> bytes = draco_bytes(g);
    Doc d = draco_doc(bytes, bytes);
    const LoadedModel draco = load_gltf(d.write(dir / "draco.gltf"));
    REQUIRE(draco.meshes.size() == 1);
    // 14 bits over a unit extent: steps of 6e-5; 10-bit octahedral normals: about 3e-3.
    check_same_corners(draco.meshes[0], plain.meshes[0], 1e-4f, 5e-3f, 5e-4f);

    json j = d.j;
    j["buffers"] = {{{"byteLength", d.blob.bytes.size()}}};
    write_glb(dir / "draco.glb", j, d.blob.bytes);
    check_same_corners(load_gltf(dir / "draco.glb").meshes[0], plain.meshes[0], 1e-4f, 5e-3f, 5e-4f);
}

TEST_CASE("glTF KHR_draco_mesh_compression with edgebreaker and without an indices accessor") {
    const fs::path dir = scratch("draco_eb");
    const GridMesh g = grid_mesh(6);
    const std::vector<uint8_t> bytes = draco_bytes(g, false);
    Doc d = draco_doc(bytes, bytes);
    d.j["meshes"][0]["primitives"][0].erase("indices");
    const LoadedModel m = load_gltf(d.write(dir / "eb.gltf"));
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].triangle_count() == g.indices.size() / 3);
    // Edgebreaker reorders faces: compare the bounds and the total area.
    const Bounds3 b = bounds(m);
    CHECK(b.lo.x == doctest::Approx(0.0).epsilon(1e-3));
    CHECK(b.hi.y == doctest::Approx(1.0).epsilon(1e-3));
    const auto area = [](const TriangleMesh& mesh) {
        double sum = 0;
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            const Vec3* p = mesh.positions.data();
            const uint32_t* i = &mesh.indices[3 * t];
            sum += 0.5 * double(length(cross(p[i[1]] - p[i[0]], p[i[2]] - p[i[0]])));
        }
        return sum;
    };
    const LoadedModel plain = load_gltf(plain_grid_doc(g).write(dir / "plain.gltf"));
    CHECK(area(m.meshes[0]) == doctest::Approx(area(plain.meshes[0])).epsilon(1e-3));
}

TEST_CASE("glTF KHR_draco_mesh_compression accessor counts must match the decoded data") {
    const fs::path dir = scratch("draco_counts");
    const std::vector<uint8_t> bytes = draco_bytes(grid_mesh());
    Doc d = draco_doc(bytes, bytes);
    d.j["accessors"][1]["count"] = 3;
    CHECK(error_of([&] {
              load_gltf(d.write(dir / "n.gltf"));
          }).find(std::string(kElement) + ".attributes.NORMAL") != std::string::npos);
    d = draco_doc(bytes, bytes);
    d.j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 7;
    const std::string e = error_of([&] { load_gltf(d.write(dir / "id.gltf")); });
    CHECK(e.find("attribute id 7") != std::string::npos);
}

TEST_CASE("glTF KHR_draco_mesh_compression corrupt bitstreams are InputErrors naming the primitive") {
    const fs::path dir = scratch("draco_corrupt");
    const std::vector<uint8_t> good = draco_bytes(grid_mesh());
    std::vector<uint8_t> bytes(good.begin(), good.begin() + std::ptrdiff_t(good.size() / 2));
    CHECK(error_of([&] { load_gltf(draco_doc(bytes, good).write(dir / "half.gltf")); }).find(kElement) !=
          std::string::npos);
    bytes = good;
    bytes[0] ^= 0xFF;  // the "DRACO" magic
    CHECK(error_of([&] { load_gltf(draco_doc(bytes, good).write(dir / "magic.gltf")); }).find(kElement) !=
          std::string::npos);
    // Every single flipped byte and every truncation: an InputError or a mesh, never a crash.
    size_t refused = 0;
    for (size_t i = 0; i < good.size(); ++i) {
        for (int variant = 0; variant < 2; ++variant) {
            bytes = good;
            if (variant == 0)
                bytes[i] ^= 0xFF;
            else
                bytes.resize(std::max<size_t>(i, 1));  // (no empty view: the test blob copies bytes)
            try {
                load_gltf(draco_doc(bytes, good).write(dir / "flip.gltf"));
            } catch (const InputError&) {
                ++refused;
            }
        }
    }
    CHECK(refused >= good.size() - 1);  // at least every truncation
}

TEST_CASE("glTF KHR_draco_mesh_compression prototype placed by EXT_mesh_gpu_instancing") {
    const fs::path dir = scratch("draco_instancing");
    const GridMesh g = grid_mesh();
    const LoadedModel plain = load_gltf(plain_grid_doc(g).write(dir / "plain.gltf"));
    const std::vector<uint8_t> bytes = draco_bytes(g);
    Doc d = draco_doc(bytes, bytes);
    const std::vector<float> moves = {0, 0, 0, 2, 0, 0, 0, 0, -3};
    d.j["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"] = {
        {"attributes", {{"TRANSLATION", d.accessor(moves, 5126, "VEC3", 3)}}}};
    d.j["extensionsRequired"] = {"KHR_draco_mesh_compression", "EXT_mesh_gpu_instancing"};
    const fs::path file = d.write(dir / "instanced.gltf");
    LoadedModel m = load_gltf(file);
    // The decoded mesh is stored once, in its own space, and placed three times.
    REQUIRE(m.prototypes.size() == 1);
    REQUIRE(m.meshes.size() == 1);
    check_same_corners(m.meshes[0], plain.meshes[0], 1e-4f, 5e-3f, 5e-4f);
    REQUIRE(m.instances.size() == 3);
    for (size_t k = 0; k < 3; ++k)
        for (size_t r = 0; r < 3; ++r)
            CHECK(m.instances[k].world_from_object.m[r][3] == doctest::Approx(moves[3 * k + r]));
    // Baked, the copies cover x in [0, 3] and z from -3 to the bump's top.
    bake_instances(m);
    CHECK(triangles(m) == 3 * g.indices.size() / 3);
    const Bounds3 b = bounds(m), one = bounds(plain);
    CHECK(b.lo.x == doctest::Approx(one.lo.x).epsilon(1e-3));
    CHECK(b.hi.x == doctest::Approx(one.hi.x + 2).epsilon(1e-3));
    CHECK(b.lo.z == doctest::Approx(one.lo.z - 3).epsilon(1e-3));
    CHECK(b.hi.z == doctest::Approx(one.hi.z).epsilon(1e-3));
}
