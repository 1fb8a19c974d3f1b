// glTF accessor decoding with every check the spec implies: tinygltf parses
// accessors but neither bounds-checks them nor applies sparse substitution.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

#include "base/error.h"
#include "io/gltf_detail.h"

namespace sahara::gltf {

/// Shared by the accessors and the compressed-data decoders (gltf_compressed.h).
std::span<const unsigned char> buffer_view_bytes(const Source& src, int bv, const std::string& element) {
    const tinygltf::Model& m = src.model;
    if (bv < 0 || size_t(bv) >= m.bufferViews.size())
        throw input_error(src.file, element, "bufferView " + std::to_string(bv) + " does not exist");
    const tinygltf::BufferView& view = m.bufferViews[size_t(bv)];
    const std::string view_name = "bufferViews[" + std::to_string(bv) + "]";
    if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
        throw input_error(src.file, view_name, "buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& data = m.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
        throw input_error(src.file, view_name,
                          "extends past the end of buffers[" + std::to_string(view.buffer) + "]");
    return {data.data() + view.byteOffset, view.byteLength};
}

namespace {

int component_size(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return 4;
        default:
            return 0;  // INT and DOUBLE are not legal in glTF 2.0 accessors
    }
}

int component_count(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR:
            return 1;
        case TINYGLTF_TYPE_VEC2:
            return 2;
        case TINYGLTF_TYPE_VEC3:
            return 3;
        case TINYGLTF_TYPE_VEC4:
        case TINYGLTF_TYPE_MAT2:
            return 4;
        case TINYGLTF_TYPE_MAT3:
            return 9;
        case TINYGLTF_TYPE_MAT4:
            return 16;
        default:
            return 0;
    }
}

/// One component at `p`, converted per the glTF "normalized" rules.
double decode(const unsigned char* p, int type, bool normalized) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? std::max(v / 127.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return normalized ? p[0] / 255.0 : p[0];
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(v / 32767.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? v / 65535.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return normalized ? v / 4294967295.0 : v;
        }
        default: {
            float v;
            std::memcpy(&v, p, 4);
            return v;
        }
    }
}

std::string accessor_name(int index) { return "accessors[" + std::to_string(index) + "]"; }

/// A validated window onto buffer bytes: elements of `elem_size` bytes every `stride`.
struct View {
    const unsigned char* data = nullptr;
    size_t stride = 0;
};

/// Resolves bufferViews[bv] and checks that `count` elements of `elem_size`
/// bytes from `offset` (with the view's stride unless `packed`) stay inside it.
View view_for(const Source& src, int bv, size_t offset, size_t count, size_t elem_size, bool packed,
              const std::string& element) {
    const std::span<const unsigned char> bytes = buffer_view_bytes(src, bv, element);
    const tinygltf::BufferView& view = src.model.bufferViews[size_t(bv)];
    const std::string view_name = "bufferViews[" + std::to_string(bv) + "]";
    const size_t stride = packed || view.byteStride == 0 ? elem_size : view.byteStride;
    if (stride < elem_size)
        throw input_error(src.file, element, "byteStride of " + view_name + " is smaller than an element");
    // count <= 2^32 and stride <= 252 keep this arithmetic far from overflow.
    if (count > (size_t(1) << 32) || offset > bytes.size() ||
        (count > 0 && (count - 1) * stride + elem_size > bytes.size() - offset))
        throw input_error(src.file, element, "reads past the end of " + view_name);
    return {bytes.data() + offset, stride};
}

/// Sparse substitution: values[k] replaces element indices[k].
void apply_sparse(const Source& src, const tinygltf::Accessor& acc, const std::string& name, int n,
                  std::vector<double>& out) {
    const auto& sp = acc.sparse;
    const std::string element = name + ".sparse";
    if (sp.count <= 0 || size_t(sp.count) > acc.count)
        throw input_error(src.file, element, "count must be between 1 and the accessor's count");
    const int isize = component_size(sp.indices.componentType);
    if (isize == 0 || sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
        sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
        throw input_error(src.file, element + ".indices", "componentType must be an unsigned integer type");
    if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0)
        throw input_error(src.file, element, "negative byteOffset");
    const size_t count = size_t(sp.count), csize = size_t(component_size(acc.componentType));
    const View iv = view_for(src, sp.indices.bufferView, size_t(sp.indices.byteOffset), count, size_t(isize),
                             true, element + ".indices");
    const View vv = view_for(src, sp.values.bufferView, size_t(sp.values.byteOffset), count,
                             csize * size_t(n), true, element + ".values");
    for (size_t k = 0; k < count; ++k) {
        const auto target = size_t(decode(iv.data + k * iv.stride, sp.indices.componentType, false));
        if (target >= acc.count)
            throw input_error(src.file, element + ".indices",
                              "index " + std::to_string(target) + " out of range");
        for (int c = 0; c < n; ++c)
            out[target * size_t(n) + size_t(c)] =
                decode(vv.data + k * vv.stride + size_t(c) * csize, acc.componentType, acc.normalized);
    }
}

}  // namespace

std::vector<double> read_accessor(const Source& src, int index, const std::string& user, int components) {
    const tinygltf::Model& m = src.model;
    if (index < 0 || size_t(index) >= m.accessors.size())
        throw input_error(src.file, user, "accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& acc = m.accessors[size_t(index)];
    const std::string name = accessor_name(index);
    const int csize = component_size(acc.componentType), n = component_count(acc.type);
    if (csize == 0)
        throw input_error(src.file, name, "invalid componentType " + std::to_string(acc.componentType));
    if (n != components)
        throw input_error(
            src.file, name,
            "has " + std::to_string(n) + " components, " + user + " needs " + std::to_string(components));
    // Without a bufferView the count is not backed by file data: cap it (16M numbers)
    // so that a few bytes of JSON cannot demand gigabytes.
    if (acc.bufferView < 0 && acc.count > (size_t(1) << 24) / size_t(n))
        throw input_error(
            src.file, name,
            "count " + std::to_string(acc.count) + " too large for an accessor without bufferView");
    std::vector<double> out;
    const size_t elem = size_t(csize) * size_t(n);
    if (acc.bufferView >= 0) {
        const View v = view_for(src, acc.bufferView, acc.byteOffset, acc.count, elem, false, name);
        out.resize(acc.count * size_t(n));
        for (size_t i = 0; i < acc.count; ++i)
            for (int c = 0; c < n; ++c)
                out[i * size_t(n) + size_t(c)] = decode(v.data + i * v.stride + size_t(c) * size_t(csize),
                                                        acc.componentType, acc.normalized);
    } else {
        out.assign(acc.count * size_t(n), 0.0);  // spec: an accessor without bufferView is all zeros
    }
    if (acc.sparse.isSparse) apply_sparse(src, acc, name, n, out);
    for (size_t i = 0; i < out.size(); ++i)
        if (!std::isfinite(out[i]))
            throw input_error(src.file, name,
                              "element " + std::to_string(i / size_t(n)) + " is not a finite number");
    return out;
}

std::vector<uint32_t> read_indices(const Source& src, int index, const std::string& user) {
    if (index >= 0 && size_t(index) < src.model.accessors.size()) {
        const int type = src.model.accessors[size_t(index)].componentType;
        if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            throw input_error(src.file, accessor_name(index), "indices must be unsigned byte, short or int");
    }
    const std::vector<double> values = read_accessor(src, index, user, 1);
    std::vector<uint32_t> out(values.size());
    for (size_t i = 0; i < values.size(); ++i) out[i] = uint32_t(values[i]);
    return out;
}

std::string uri_decode(const std::string& uri) {
    auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) && hex(uri[i + 2])) {
            out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

}  // namespace sahara::gltf
