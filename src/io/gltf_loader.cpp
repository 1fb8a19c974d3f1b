// glTF 2.0 (.gltf with external or embedded buffers, .glb) via tinygltf, which
// parses JSON and buffers; everything tinygltf leaves unchecked or unapplied
// (accessor bounds, sparse accessors, node cycles, required extensions) is done here.
#include <nlohmann/json.hpp>

#include <cstring>
#include <iterator>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include "base/error.h"
#include "base/log.h"
#include "io/files.h"
#include "io/gltf_compressed.h"
#include "io/gltf_detail.h"
#include "io/mesh_utils.h"

namespace sahara {

namespace {

using gltf::Source;

/// Extensions sahara understands; any other in extensionsRequired is refused.
const std::set<std::string> kSupportedRequired = {
    "KHR_texture_transform",      "KHR_materials_emissive_strength",
    "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_volume",       "KHR_lights_punctual",
    "KHR_mesh_quantization",      "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",    "EXT_mesh_gpu_instancing",
    "KHR_materials_variants"};
/// More of them: material models and image formats.
const std::set<std::string> kSupportedRequiredMaterials = {
    "KHR_materials_unlit",      "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_specular",   "EXT_texture_webp",
    "KHR_materials_clearcoat",  "KHR_materials_sheen",
    "KHR_materials_anisotropy", "KHR_materials_iridescence",
    "KHR_materials_dispersion", "KHR_materials_diffuse_transmission"};

bool supported_required(const std::string& name) {
    return kSupportedRequired.count(name) || kSupportedRequiredMaterials.count(name);
}

/// "major.minor" as two numbers; nothing if the text is not of that form.
std::optional<std::pair<int, int>> version_numbers(const std::string& text) {
    int major = 0, minor = 0;
    char dot = 0, extra = 0;
    std::istringstream in(text);
    if (!(in >> major >> dot >> minor) || dot != '.' || (in >> extra)) return std::nullopt;
    return std::make_pair(major, minor);
}

/// A 2.0 loader must refuse files whose minVersion is above 2.0 (glTF 2.0, "Versioning").
void check_version(const std::string& file, const nlohmann::json& doc) {
    auto asset = doc.find("asset");
    if (asset == doc.end() || !asset->is_object()) return;  // tinygltf names a missing asset
    if (auto min = asset->find("minVersion"); min != asset->end() && min->is_string()) {
        const auto v = version_numbers(min->get<std::string>());
        if (!v)
            throw input_error(file, "asset.minVersion",
                              "'" + min->get<std::string>() + "' is not major.minor");
        if (*v > std::make_pair(2, 0))
            throw input_error(file, "asset.minVersion",
                              min->get<std::string>() + " is required, this loader reads glTF 2.0");
    }
    if (auto ver = asset->find("version"); ver != asset->end() && ver->is_string()) {
        const auto v = version_numbers(ver->get<std::string>());
        if (v && v->first != 2)
            throw input_error(file, "asset.version", ver->get<std::string>() + " is not glTF 2.x");
    }
}

uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

bool is_glb(const std::vector<unsigned char>& bytes) {
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

/// The JSON text of a .gltf, or of a .glb's first chunk, and the size of a
/// .glb's BIN chunk (0 if none).
struct JsonPart {
    std::string_view text;
    bool glb = false;
    size_t bin_size = 0;
};

JsonPart json_part(const std::string& file, const std::vector<unsigned char>& bytes) {
    if (!is_glb(bytes))
        return {std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), false, 0};
    if (bytes.size() < 20) throw input_error(file, "GLB header", "file is shorter than the 20-byte header");
    if (le32(&bytes[4]) != 2)
        throw input_error(file, "GLB header", "version " + std::to_string(le32(&bytes[4])) + ", expected 2");
    if (le32(&bytes[8]) > bytes.size())
        throw input_error(file, "GLB header", "length is larger than the file");
    const size_t json_len = le32(&bytes[12]);
    if (le32(&bytes[16]) != 0x4E4F534Au) throw input_error(file, "GLB chunk 0", "is not the JSON chunk");
    if (json_len > bytes.size() - 20) throw input_error(file, "GLB chunk 0", "runs past the end of the file");
    JsonPart part{std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, json_len), true, 0};
    const size_t bin_at = 20 + ((json_len + 3) & ~size_t(3));
    if (bin_at + 8 <= bytes.size() && le32(&bytes[bin_at + 4]) == 0x004E4942u)
        part.bin_size = std::min<size_t>(le32(&bytes[bin_at]), bytes.size() - bin_at - 8);
    return part;
}

/// Checks made before tinygltf sees the file, so that the messages can name the
/// element: unsupported required extensions and buffers larger than their data.
void precheck(const std::string& file, const std::filesystem::path& dir, const JsonPart& part) {
    const nlohmann::json doc = nlohmann::json::parse(part.text.begin(), part.text.end(), nullptr, false);
    if (!doc.is_object()) return;  // tinygltf reports the syntax error
    check_version(file, doc);
    if (auto req = doc.find("extensionsRequired"); req != doc.end() && req->is_array())
        for (const auto& ext : *req)
            if (ext.is_string() && !supported_required(ext.get<std::string>()))
                throw input_error(file, "extensionsRequired", ext.get<std::string>() + " is not supported");
    auto buffers = doc.find("buffers");
    if (buffers == doc.end() || !buffers->is_array()) return;
    for (size_t i = 0; i < buffers->size(); ++i) {
        const auto& b = (*buffers)[i];
        if (!b.is_object() || !b.contains("byteLength") || !b["byteLength"].is_number_unsigned()) continue;
        const auto length = b["byteLength"].get<uint64_t>();
        const std::string element = "buffers[" + std::to_string(i) + "]";
        if (!b.contains("uri")) {
            if (i == 0 && part.glb && length > part.bin_size)
                throw input_error(file, element,
                                  "byteLength " + std::to_string(length) +
                                      " is larger than the GLB BIN chunk (" + std::to_string(part.bin_size) +
                                      " bytes)");
            continue;
        }
        if (!b["uri"].is_string()) continue;
        const std::string uri = b["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        const std::filesystem::path path = dir / gltf::uri_decode(uri);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec))
            throw input_error(file, element, "file " + uri + " not found");
        const auto size = std::filesystem::file_size(path, ec);
        if (!ec && length > size)
            throw input_error(file, element,
                              "byteLength " + std::to_string(length) + " is larger than " + uri + " (" +
                                  std::to_string(size) + " bytes)");
    }
}

/// tinygltf image callback: keeps the encoded bytes of data: URI images for
/// sahara's decoder and ignores the rest (external files and bufferViews are
/// decoded later, with their bounds checked).
bool stash_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
    if (image->uri.empty() && image->bufferView < 0 && bytes != nullptr && size > 0)
        static_cast<Source*>(user)->data_uri_images[index].assign(bytes, bytes + size);
    return true;
}

/// One line of tinygltf's (possibly multi-line, possibly huge) error text.
std::string first_line(const std::string& text) {
    std::string line = text.substr(0, text.find('\n'));
    if (line.size() > 200) line = line.substr(0, 200) + "...";
    return line.empty() ? "unknown error" : line;
}

void parse(Source& src, const std::vector<unsigned char>& bytes) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(stash_image, &src);
    std::string err, warn;
    bool ok = false;
    if (bytes.size() > 0xFFFFFFFFu) throw input_error(src.file, "", "file is larger than 4 GB");
    try {
        const std::string base = src.dir.string();
        ok = is_glb(bytes) ? loader.LoadBinaryFromMemory(&src.model, &err, &warn, bytes.data(),
                                                         unsigned(bytes.size()), base)
                           : loader.LoadASCIIFromString(&src.model, &err, &warn,
                                                        reinterpret_cast<const char*>(bytes.data()),
                                                        unsigned(bytes.size()), base);
    } catch (const std::exception& e) {
        throw input_error(src.file, "", std::string("malformed glTF: ") + e.what());
    }
    if (!ok) throw input_error(src.file, "", "malformed glTF: " + first_line(err));
}

}  // namespace

LoadedModel load_gltf(const std::filesystem::path& file, const Mat4& world_from_model, SharedMeshes shared,
                      const std::optional<std::string>& variant) {
    Source src;
    src.file = file.string();
    src.dir = file.parent_path();
    const std::vector<unsigned char> bytes = read_file_bytes(file);
    const JsonPart part = json_part(src.file, bytes);
    precheck(src.file, src.dir, part);
    const auto prepared = gltf::prepared_for_tinygltf(bytes, part.text, part.glb);
    parse(src, prepared ? *prepared : bytes);
    gltf::decode_meshopt_views(src);  // first: a Draco bitstream may sit in a meshopt bufferView
    gltf::decode_draco_primitives(src);
    if (variant) src.variant = gltf::chosen_variant(src, *variant);
    LoadedModel out;
    gltf::build_scene(src, world_from_model, shared, out);
    out.variants = gltf::variant_names(src.model);
    out.variant = variant;
    if (out.dropped_degenerate > 0)
        log_info(src.file + ": dropped " + std::to_string(out.dropped_degenerate) + " zero-area triangles");
    return out;
}

}  // namespace sahara
