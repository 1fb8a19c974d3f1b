// EXT_meshopt_compression: a bufferView's compressed bytes (in the buffer its
// extension names) are decoded with meshoptimizer into a buffer of its own, and
// the bufferView is pointed at it; accessors then read it as uncompressed data.
#include <meshoptimizer.h>

#include <cstring>

#include "base/error.h"
#include "io/gltf_compressed.h"

namespace sahara::gltf {

namespace {

/// The extension object of one bufferView, as its specification defines it.
struct Compressed {
    int buffer = -1;
    size_t offset = 0, length = 0, stride = 0, count = 0;
    std::string mode, filter = "NONE";
};

/// A non-negative integer member of `obj` (`fallback` if absent and given).
size_t member(const Source& src, const tinygltf::Value& obj, const char* key, const std::string& element,
              std::optional<size_t> fallback = std::nullopt) {
    const tinygltf::Value& v = obj.Get(key);
    if (!obj.Has(key) && fallback) return *fallback;
    if (!v.IsNumber() || !(v.GetNumberAsDouble() >= 0.0 && v.GetNumberAsDouble() <= 4294967295.0))
        throw input_error(src.file, element + "." + key, "must be a non-negative integer below 2^32");
    return size_t(v.GetNumberAsDouble());
}

std::string text_member(const tinygltf::Value& obj, const char* key, const char* fallback) {
    const tinygltf::Value& v = obj.Get(key);
    return v.IsString() ? v.Get<std::string>() : (obj.Has(key) ? "" : fallback);
}

Compressed parse(const Source& src, const tinygltf::Value& ext, const tinygltf::BufferView& view,
                 const std::string& element) {
    Compressed c;
    c.buffer = int(member(src, ext, "buffer", element));
    c.offset = member(src, ext, "byteOffset", element, 0);
    c.length = member(src, ext, "byteLength", element);
    c.stride = member(src, ext, "byteStride", element);
    c.count = member(src, ext, "count", element);
    c.mode = text_member(ext, "mode", "");
    c.filter = text_member(ext, "filter", "NONE");
    const auto fail = [&](const std::string& why) { throw input_error(src.file, element, why); };
    if (c.mode != "ATTRIBUTES" && c.mode != "TRIANGLES" && c.mode != "INDICES")
        fail("mode must be ATTRIBUTES, TRIANGLES or INDICES");
    if (c.filter != "NONE" && c.filter != "OCTAHEDRAL" && c.filter != "QUATERNION" &&
        c.filter != "EXPONENTIAL")
        fail("filter must be NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
    if (view.byteStride != 0 && view.byteStride != c.stride) fail("byteStride differs from the bufferView's");
    if (view.byteLength != c.stride * c.count) fail("the bufferView's byteLength is not byteStride x count");
    if (c.mode == "ATTRIBUTES" && (c.stride == 0 || c.stride % 4 != 0 || c.stride > 256))
        fail("byteStride of ATTRIBUTES must be a multiple of 4 up to 256");
    if (c.mode != "ATTRIBUTES" && c.stride != 2 && c.stride != 4)
        fail("byteStride of indices must be 2 or 4");
    if (c.mode != "ATTRIBUTES" && c.filter != "NONE") fail("indices take no filter");
    if (c.mode == "TRIANGLES" && c.count % 3 != 0) fail("count of TRIANGLES must be a multiple of 3");
    if (c.filter == "OCTAHEDRAL" && c.stride != 4 && c.stride != 8)
        fail("OCTAHEDRAL needs byteStride 4 or 8");
    if (c.filter == "QUATERNION" && c.stride != 8) fail("QUATERNION needs byteStride 8");
    // The codecs spend at least 2 bits per 16 decoded bytes: a larger claim is not
    // backed by the data and must not make a small file allocate gigabytes.
    if (c.stride * c.count > 256 * c.length + 65536)
        fail("count x byteStride is more than " + std::to_string(c.length) + " compressed bytes can hold");
    return c;
}

std::vector<unsigned char> decode(const Source& src, const Compressed& c, const std::string& element) {
    std::vector<unsigned char> out(c.stride * c.count);
    if (c.count == 0) return out;
    if (c.buffer < 0 || size_t(c.buffer) >= src.model.buffers.size())
        throw input_error(src.file, element + ".buffer",
                          "buffer " + std::to_string(c.buffer) + " does not exist");
    const std::vector<unsigned char>& data = src.model.buffers[size_t(c.buffer)].data;
    if (c.offset > data.size() || c.length > data.size() - c.offset)
        throw input_error(src.file, element,
                          "extends past the end of buffers[" + std::to_string(c.buffer) + "]");
    const unsigned char* in = data.data() + c.offset;
    int status = 0;
    if (c.mode == "ATTRIBUTES")
        status = meshopt_decodeVertexBuffer(out.data(), c.count, c.stride, in, c.length);
    else if (c.mode == "TRIANGLES")
        status = meshopt_decodeIndexBuffer(out.data(), c.count, c.stride, in, c.length);
    else
        status = meshopt_decodeIndexSequence(out.data(), c.count, c.stride, in, c.length);
    if (status != 0)
        throw input_error(src.file, element,
                          "corrupt meshopt data (decoder status " + std::to_string(status) + ")");
    if (c.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), c.count, c.stride);
    if (c.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), c.count, c.stride);
    if (c.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), c.count, c.stride);
    return out;
}

}  // namespace

void decode_meshopt_views(Source& src) {
    for (size_t i = 0; i < src.model.bufferViews.size(); ++i) {
        auto ext = src.model.bufferViews[i].extensions.find(kMeshopt);
        if (ext == src.model.bufferViews[i].extensions.end()) continue;
        const std::string element = "bufferViews[" + std::to_string(i) + "].extensions." + kMeshopt;
        if (!ext->second.IsObject()) throw input_error(src.file, element, "is not an object");
        const Compressed c = parse(src, ext->second, src.model.bufferViews[i], element);
        tinygltf::Buffer decoded;
        decoded.data = decode(src, c, element);
        src.model.buffers.push_back(std::move(decoded));
        tinygltf::BufferView& view = src.model.bufferViews[i];  // after the push: no reference into buffers
        view.buffer = int(src.model.buffers.size()) - 1;
        view.byteOffset = 0;
    }
}

}  // namespace sahara::gltf
