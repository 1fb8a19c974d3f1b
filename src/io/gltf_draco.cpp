// KHR_draco_mesh_compression: each primitive's Draco bitstream is decoded with
// libdraco and written, in the componentType its accessors declare, into a new
// buffer that those accessors are pointed at (the extension's spec: accessor
// bufferViews are ignored and the decoded data fills the accessors).
#include <draco/compression/decode.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <memory>

#include "base/error.h"
#include "io/gltf_compressed.h"

namespace sahara::gltf {

namespace {

template <class T>
void append(std::vector<unsigned char>& out, const T* values, size_t n) {
    const size_t at = out.size();
    out.resize(at + n * sizeof(T));
    std::memcpy(out.data() + at, values, n * sizeof(T));
}

/// The values of `attr` for every point, `n` components of type T each; false
/// if a value does not convert (out of range for T, or past the attribute's data).
template <class T>
bool convert(const draco::PointAttribute& attr, size_t points, int n, std::vector<unsigned char>& out) {
    std::array<T, 16> v{};
    for (size_t i = 0; i < points; ++i) {
        const draco::AttributeValueIndex value = attr.mapped_index(draco::PointIndex(uint32_t(i)));
        if (value.value() >= attr.size() || !attr.ConvertValue<T>(value, int8_t(n), v.data())) return false;
        append(out, v.data(), size_t(n));
    }
    return true;
}

bool convert(const draco::PointAttribute& attr, size_t points, int n, int component_type,
             std::vector<unsigned char>& out) {
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return convert<int8_t>(attr, points, n, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return convert<uint8_t>(attr, points, n, out);
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return convert<int16_t>(attr, points, n, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return convert<uint16_t>(attr, points, n, out);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return convert<uint32_t>(attr, points, n, out);
        default:
            return convert<float>(attr, points, n, out);
    }
}

/// One primitive's decoding: the decoded bytes go to one new buffer, a
/// bufferView per accessor.
class DracoPrimitive {
   public:
    DracoPrimitive(Source& src, tinygltf::Primitive& prim, std::string element, std::map<int, int>& owners,
                   int prim_id)
        : src_(src), prim_(prim), element_(std::move(element)), owners_(owners), prim_id_(prim_id) {}

    void decode(const tinygltf::Value& ext) {
        const tinygltf::Value& bv = ext.Get("bufferView");
        if (!bv.IsNumber()) throw input_error(src_.file, element_ + ".bufferView", "is missing");
        mesh_ = decode_mesh(bv.GetNumberAsInt());
        buffer_ = int(src_.model.buffers.size());
        src_.model.buffers.emplace_back();
        const tinygltf::Value& attrs = ext.Get("attributes");
        if (!attrs.IsObject()) throw input_error(src_.file, element_ + ".attributes", "is missing");
        for (const std::string& semantic : attrs.Keys()) {
            const tinygltf::Value& id = attrs.Get(semantic);
            if (!id.IsNumber() || id.GetNumberAsInt() < 0)
                throw input_error(src_.file, element_ + ".attributes." + semantic, "is not an attribute id");
            fill_attribute(semantic, uint32_t(id.GetNumberAsInt()));
        }
        fill_indices();
    }

   private:
    std::unique_ptr<draco::Mesh> decode_mesh(int bv) {
        const std::span<const unsigned char> bytes = buffer_view_bytes(src_, bv, element_ + ".bufferView");
        draco::DecoderBuffer buffer;
        buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
        const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
        if (!type.ok())
            throw input_error(src_.file, element_, "not Draco data: " + type.status().error_msg_string());
        if (type.value() != draco::TRIANGULAR_MESH)
            throw input_error(src_.file, element_, "the Draco data is not a triangle mesh");
        draco::Decoder decoder;
        auto mesh = decoder.DecodeMeshFromBuffer(&buffer);
        if (!mesh.ok())
            throw input_error(src_.file, element_, "corrupt Draco data: " + mesh.status().error_msg_string());
        return std::move(mesh).value();
    }

    void fill_attribute(const std::string& semantic, uint32_t id) {
        const std::string element = element_ + ".attributes." + semantic;
        auto it = prim_.attributes.find(semantic);
        if (it == prim_.attributes.end())
            throw input_error(src_.file, element, "is not an attribute of the primitive");
        const draco::PointAttribute* attr = mesh_->GetAttributeByUniqueId(id);
        if (attr == nullptr)
            throw input_error(src_.file, element,
                              "attribute id " + std::to_string(id) + " is not in the Draco data");
        const int index = claim(it->second, element);
        it->second = index;
        const tinygltf::Accessor& acc = src_.model.accessors[size_t(index)];
        const size_t points = mesh_->num_points();
        if (acc.count != points)
            throw input_error(src_.file, element,
                              "accessor count " + std::to_string(acc.count) + " differs from the " +
                                  std::to_string(points) + " decoded points");
        const int n = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (n <= 0 || n > 16 || n != attr->num_components())
            throw input_error(src_.file, element,
                              "the Draco attribute has " + std::to_string(attr->num_components()) +
                                  " components, the accessor's type " + std::to_string(std::max(n, 0)));
        std::vector<unsigned char> bytes;
        if (!convert(*attr, points, n, acc.componentType, bytes))
            throw input_error(src_.file, element, "decoded values do not fit the accessor's componentType");
        point_at(index, bytes);
    }

    /// Faces become a triangle list (also for a TRIANGLE_STRIP primitive: Draco stores faces).
    void fill_indices() {
        const size_t count = size_t(mesh_->num_faces()) * 3;
        std::vector<uint32_t> idx(count);
        for (uint32_t f = 0; f < mesh_->num_faces(); ++f)
            for (size_t k = 0; k < 3; ++k) idx[3 * f + k] = mesh_->face(draco::FaceIndex(f))[k].value();
        const std::string element = element_ + ".indices";
        if (prim_.indices < 0) {  // the file's vertices are in triangle order: add an index accessor
            tinygltf::Accessor acc;
            acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            acc.type = TINYGLTF_TYPE_SCALAR;
            acc.count = count;
            src_.model.accessors.push_back(acc);
            prim_.indices = int(src_.model.accessors.size()) - 1;
        } else {
            prim_.indices = claim(prim_.indices, element);
        }
        tinygltf::Accessor& acc = src_.model.accessors[size_t(prim_.indices)];
        if (prim_.mode == TINYGLTF_MODE_TRIANGLE_STRIP) acc.count = count;
        prim_.mode = TINYGLTF_MODE_TRIANGLES;
        if (acc.count != count)
            throw input_error(src_.file, element,
                              "accessor count " + std::to_string(acc.count) + " differs from the " +
                                  std::to_string(count) + " decoded indices");
        size_t size = 0;  // other component types are left for read_indices to refuse
        if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) size = 1;
        if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) size = 2;
        if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) size = 4;
        if (size == 0) return;
        std::vector<unsigned char> bytes;
        for (uint32_t i : idx) {
            if (size < 4 && i >> (8 * size) != 0)
                throw input_error(src_.file, element, "decoded index " + std::to_string(i) + " does not fit");
            for (size_t b = 0; b < size; ++b) bytes.push_back(uint8_t(i >> (8 * b)));
        }
        point_at(prim_.indices, bytes);
    }

    /// `index`, or a copy of it if another Draco primitive already filled it
    /// (each primitive's decoded data is its own).
    int claim(int index, const std::string& element) {
        if (index < 0 || size_t(index) >= src_.model.accessors.size())
            throw input_error(src_.file, element, "accessor " + std::to_string(index) + " does not exist");
        auto [it, fresh] = owners_.emplace(index, prim_id_);
        if (fresh || it->second == prim_id_) return index;
        src_.model.accessors.push_back(src_.model.accessors[size_t(index)]);
        return int(src_.model.accessors.size()) - 1;
    }

    void point_at(int accessor, const std::vector<unsigned char>& bytes) {
        tinygltf::Accessor& acc = src_.model.accessors[size_t(accessor)];
        acc.bufferView = append_buffer_view(src_, buffer_, bytes);
        acc.byteOffset = 0;
        acc.sparse.isSparse = false;  // sparse data belongs to the uncompressed fallback
    }

    Source& src_;
    tinygltf::Primitive& prim_;
    std::string element_;
    std::map<int, int>& owners_;  ///< accessor -> the Draco primitive that filled it
    int prim_id_;
    std::unique_ptr<draco::Mesh> mesh_;
    int buffer_ = -1;
};

}  // namespace

void decode_draco_primitives(Source& src) {
    std::map<int, int> owners;
    int prim_id = 0;
    for (size_t m = 0; m < src.model.meshes.size(); ++m) {
        auto& prims = src.model.meshes[m].primitives;
        for (size_t p = 0; p < prims.size(); ++p, ++prim_id) {
            auto ext = prims[p].extensions.find(kDraco);
            if (ext == prims[p].extensions.end()) continue;
            // Points and lines are skipped by the reader; Draco allows neither.
            if (prims[p].mode != TINYGLTF_MODE_TRIANGLES && prims[p].mode != TINYGLTF_MODE_TRIANGLE_STRIP)
                continue;
            const std::string element = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) +
                                        "].extensions." + kDraco;
            try {
                DracoPrimitive(src, prims[p], element, owners, prim_id).decode(ext->second);
            } catch (const std::bad_alloc&) {
                throw input_error(src.file, element, "the Draco data asks for more memory than there is");
            }
        }
    }
}

}  // namespace sahara::gltf
