#pragma once
// Helpers of the glTF loader tests: glTF documents, buffers, PNGs and .glb
// files built in code (the tests never read ../shared).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "io/image_io.h"
#include "io/mesh_utils.h"
#include "io/model_loader.h"
#include "error_message.h"
#include "scratch_dir.h"

namespace sahara::test::gltf {

namespace fs = std::filesystem;
using nlohmann::json;

/// A fresh folder for one test's files. The process id keeps test cases that
/// share a name apart when ctest runs them in parallel processes.
inline fs::path scratch(const std::string& name) { return scratch_dir("gltf_" + name); }

inline std::vector<uint8_t> read_all(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const fs::path& f, const std::vector<uint8_t>& b) {
    std::ofstream(f, std::ios::binary)
        .write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

inline void write_text(const fs::path& f, const std::string& s) { std::ofstream(f, std::ios::binary) << s; }

inline std::string base64(const std::vector<uint8_t>& in) {
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
inline void write_glb(const fs::path& file, json j, std::vector<uint8_t> bin) {
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
inline json json_of(const fs::path& file) {
    const std::vector<uint8_t> b = read_all(file);
    if (b.size() >= 20 && std::memcmp(b.data(), "glTF", 4) == 0) {
        uint32_t len;
        std::memcpy(&len, &b[12], 4);
        return json::parse(b.begin() + 20, b.begin() + 20 + len);
    }
    return json::parse(b);
}

inline size_t triangles(const LoadedModel& m) {
    size_t n = 0;
    for (const auto& mesh : m.meshes) n += mesh.triangle_count();
    return n;
}

inline Bounds3 bounds(const LoadedModel& m) {
    Bounds3 b;
    for (const auto& mesh : m.meshes) b.extend(mesh_bounds(mesh));
    return b;
}

using sahara::test::error_of;

inline const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

inline Vec3 face_normal(const TriangleMesh& m, size_t t) {
    const auto& p = m.positions;
    const uint32_t* i = &m.indices[3 * t];
    return triangle_normal(p[i[0]], p[i[1]], p[i[2]]);
}

/// A 2x2 RGBA PNG (written through OpenImageIO): top row red, (0,128,0,128); bottom row blue, white.
inline std::vector<uint8_t> tiny_png(const fs::path& dir) {
    const uint8_t px[16] = {255, 0, 0, 255, 0, 128, 0, 128, 0, 0, 255, 255, 255, 255, 255, 255};
    const fs::path file = dir / "tiny.png";
    write_image_u8(file, 2, 2, 4, px);
    return read_all(file);
}

/// A one-triangle document whose primitive uses material 0, with uvs.
inline Doc textured_doc(const json& material) {
    Doc d;
    const int uv = d.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, 5126, "VEC2", 3);
    d.node({{"mesh", d.mesh(d.positions(kTriangle), -1, 4, {{"TEXCOORD_0", uv}})}});
    d.j["meshes"][0]["primitives"][0]["material"] = 0;
    d.j["materials"] = {material};
    return d;
}

/// A PNG assembled chunk by chunk (valid CRCs): RGBA8 `w` x `h`, IDAT bytes as given.
inline std::vector<uint8_t> handmade_png(uint32_t w, uint32_t h, const std::vector<uint8_t>& idat) {
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

}  // namespace sahara::test::gltf
