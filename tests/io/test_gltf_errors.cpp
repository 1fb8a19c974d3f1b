#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "gltf_test_doc.h"
#include "scene/texture.h"

using namespace sahara;
using namespace sahara::test::gltf;

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
        d.j["extensionsUsed"] = {"KHR_texture_basisu"};
        d.j["extensionsRequired"] = {"KHR_texture_basisu"};
        CHECK(load(d) == f + ": extensionsRequired: KHR_texture_basisu is not supported");
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

TEST_CASE("glTF asset.minVersion above 2.0 and unknown asset versions are refused") {
    const fs::path dir = scratch("versions");
    const std::string f = (dir / "v.gltf").string();
    auto load_with = [&](const json& asset) {
        Doc d;
        d.node({{"mesh", d.mesh(d.positions(kTriangle))}});
        d.j["asset"] = asset;
        return error_of([&] { load_gltf(d.write(dir / "v.gltf")); });
    };
    CHECK(load_with({{"version", "2.1"}, {"minVersion", "2.1"}}) ==
          f + ": asset.minVersion: 2.1 is required, this loader reads glTF 2.0");
    CHECK(load_with({{"version", "3.0"}}) == f + ": asset.version: 3.0 is not glTF 2.x");
    CHECK(load_with({{"version", "2.0"}, {"minVersion", "two"}}) ==
          f + ": asset.minVersion: 'two' is not major.minor");
    // A 2.x file that a 2.0 loader may read: accepted.
    CHECK(load_with({{"version", "2.3"}, {"minVersion", "2.0"}}) == "(no InputError)");
}

TEST_CASE("glTF extensionsRequired: the material extensions sahara implements pass and others are refused") {
    const fs::path dir = scratch("required");
    const std::string f = (dir / "r.gltf").string();
    for (const char* ext :
         {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
          "KHR_materials_emissive_strength", "KHR_texture_transform", "KHR_materials_iridescence",
          "KHR_materials_dispersion", "KHR_materials_diffuse_transmission"}) {
        CAPTURE(ext);
        Doc d;
        d.node({{"mesh", d.mesh(d.positions(kTriangle))}});
        d.j["extensionsUsed"] = {ext};
        d.j["extensionsRequired"] = {ext};
        CHECK(error_of([&] { load_gltf(d.write(dir / "r.gltf")); }) == "(no InputError)");
    }
    Doc d;
    d.node({{"mesh", d.mesh(d.positions(kTriangle))}});
    d.j["extensionsRequired"] = {"KHR_materials_transmission", "KHR_materials_volume_scatter"};
    CHECK(error_of([&] { load_gltf(d.write(dir / "r.gltf")); }) ==
          f + ": extensionsRequired: KHR_materials_volume_scatter is not supported");
}
