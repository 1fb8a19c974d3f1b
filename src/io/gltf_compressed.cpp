// What tinygltf must not see of compressed files (it would refuse them before
// sahara decodes anything), and the buffer helpers both decoders share.
#include <nlohmann/json.hpp>

#include <set>

#include "base/error.h"
#include "io/gltf_compressed.h"

namespace sahara::gltf {

namespace {

bool has_extension(const nlohmann::json& element, const char* name) {
    return element.is_object() && element.contains("extensions") && element["extensions"].is_object() &&
           element["extensions"].contains(name);
}

/// tinygltf refuses a buffer without uri in a .gltf (and takes the BIN chunk
/// for one in a .glb): meshopt's fallback buffers get a tiny data URI instead.
/// They are never read, their bufferViews are pointed at the decoded data.
bool give_fallbacks_placeholders(nlohmann::json& doc, bool glb) {
    if (!doc.contains("bufferViews") || !doc["bufferViews"].is_array()) return false;
    if (!doc.contains("buffers") || !doc["buffers"].is_array()) return false;
    std::set<size_t> fallbacks;
    for (const auto& view : doc["bufferViews"])
        if (has_extension(view, kMeshopt) && view.contains("buffer") && view["buffer"].is_number_unsigned())
            fallbacks.insert(view["buffer"].get<size_t>());
    bool changed = false;
    for (size_t i : fallbacks) {
        if (i >= doc["buffers"].size() || (glb && i == 0)) continue;
        nlohmann::json& b = doc["buffers"][i];
        if (!b.is_object() || b.contains("uri")) continue;
        b["uri"] = "data:application/octet-stream;base64,AAAA";  // 3 zero bytes
        b["byteLength"] = 3;
        changed = true;
    }
    return changed;
}

/// tinygltf refuses an indices accessor without bufferView, which is how Draco
/// primitives come: it gets the Draco bufferView, replaced once decoded.
bool give_draco_indices_a_view(nlohmann::json& doc) {
    if (!doc.contains("meshes") || !doc["meshes"].is_array()) return false;
    if (!doc.contains("accessors") || !doc["accessors"].is_array()) return false;
    bool changed = false;
    for (const auto& mesh : doc["meshes"]) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (const auto& prim : mesh["primitives"]) {
            if (!has_extension(prim, kDraco) || !prim.contains("indices") ||
                !prim["indices"].is_number_unsigned())
                continue;
            const auto& ext = prim["extensions"][kDraco];
            const size_t indices = prim["indices"].get<size_t>();
            if (!ext.is_object() || !ext.contains("bufferView") || indices >= doc["accessors"].size())
                continue;
            nlohmann::json& acc = doc["accessors"][indices];
            if (!acc.is_object() || acc.contains("bufferView")) continue;
            acc["bufferView"] = ext["bufferView"];
            changed = true;
        }
    }
    return changed;
}

/// `file_bytes` with its JSON replaced by `text` (a .glb keeps its other chunks).
std::vector<unsigned char> with_json(const std::vector<unsigned char>& file_bytes, std::string_view json,
                                     bool glb, std::string text) {
    if (!glb) return std::vector<unsigned char>(text.begin(), text.end());
    while (text.size() % 4) text += ' ';
    const size_t json_at = size_t(reinterpret_cast<const unsigned char*>(json.data()) - file_bytes.data());
    const size_t rest = std::min(file_bytes.size(), json_at + ((json.size() + 3) & ~size_t(3)));
    std::vector<unsigned char> out(file_bytes.begin(), file_bytes.begin() + 20);
    out.insert(out.end(), text.begin(), text.end());
    out.insert(out.end(), file_bytes.begin() + std::ptrdiff_t(rest), file_bytes.end());
    const auto put32 = [&](size_t at, size_t v) {
        for (size_t k = 0; k < 4; ++k) out[at + k] = uint8_t(v >> (8 * k));
    };
    put32(8, out.size());
    put32(12, text.size());
    return out;
}

}  // namespace

std::optional<std::vector<unsigned char>> prepared_for_tinygltf(const std::vector<unsigned char>& file_bytes,
                                                                std::string_view json, bool glb) {
    if (json.find(kMeshopt) == std::string_view::npos && json.find(kDraco) == std::string_view::npos)
        return std::nullopt;
    nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
    if (!doc.is_object()) return std::nullopt;
    const bool placeholders = give_fallbacks_placeholders(doc, glb);
    if (!give_draco_indices_a_view(doc) && !placeholders) return std::nullopt;
    return with_json(file_bytes, json, glb, doc.dump());
}

int append_buffer_view(Source& src, int buffer, const std::vector<unsigned char>& bytes) {
    std::vector<unsigned char>& data = src.model.buffers[size_t(buffer)].data;
    data.resize((data.size() + 3) & ~size_t(3));
    tinygltf::BufferView view;
    view.buffer = buffer;
    view.byteOffset = data.size();
    view.byteLength = bytes.size();
    data.insert(data.end(), bytes.begin(), bytes.end());
    src.model.bufferViews.push_back(view);
    return int(src.model.bufferViews.size()) - 1;
}

}  // namespace sahara::gltf
