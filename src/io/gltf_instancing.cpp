// EXT_mesh_gpu_instancing: per-instance TRANSLATION, ROTATION and SCALE
// accessors on a node, read into one node-space matrix per instance; custom
// attributes (`_ID`, ...) only count the instances.
#include <cmath>
#include <optional>

#include "base/error.h"
#include "io/gltf_detail.h"

namespace sahara::gltf {

namespace {

/// One instancing attribute: its name, components, and whether a component type may carry it.
struct Attribute {
    const char* name;
    int components;
    bool (*accepts)(int component_type, bool normalized);
};

/// Floats, or (KHR_mesh_quantization) 8- and 16-bit integers.
bool accepts_vector(int type, bool) {
    return type == TINYGLTF_COMPONENT_TYPE_FLOAT || type == TINYGLTF_COMPONENT_TYPE_BYTE ||
           type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT ||
           type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
}

/// Floats, or normalized signed bytes and shorts (a quaternion's components lie in [-1, 1]).
bool accepts_quaternion(int type, bool normalized) {
    return type == TINYGLTF_COMPONENT_TYPE_FLOAT ||
           (normalized && (type == TINYGLTF_COMPONENT_TYPE_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT));
}

const Attribute kTranslation{"TRANSLATION", 3, accepts_vector};
const Attribute kRotation{"ROTATION", 4, accepts_quaternion};
const Attribute kScale{"SCALE", 3, accepts_vector};

/// How far a stored quaternion's length may stray from 1: normalized bytes round
/// each component by up to 1/254, which moves the length by less than this.
constexpr double kUnitTolerance = 0.01;

class InstancingReader {
   public:
    InstancingReader(const Source& src, const tinygltf::Value& attributes, std::string element)
        : src_(src), attributes_(attributes), element_(std::move(element)) {}

    /// The attribute's numbers (components per instance), empty if the node does not give it.
    std::vector<double> read(const Attribute& a) {
        if (!attributes_.Has(a.name)) return {};
        const std::string element = element_ + "." + a.name;
        const int index = accessor_index(element, attributes_.Get(a.name));
        const tinygltf::Accessor& acc = src_.model.accessors[size_t(index)];
        const int want = a.components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
        if (acc.type != want)
            throw input_error(
                src_.file, element,
                "accessor " + std::to_string(index) + " must be a VEC" + std::to_string(a.components));
        if (!a.accepts(acc.componentType, acc.normalized))
            throw input_error(src_.file, element,
                              "accessor " + std::to_string(index) + " has componentType " +
                                  std::to_string(acc.componentType) +
                                  (a.components == 4 ? ", expected float or normalized byte or short"
                                                     : ", expected float, byte or short"));
        take_count(element, acc.count);
        try {
            return read_accessor(src_, index, element, a.components);
        } catch (const InputError& e) {
            // The accessor's own message, placed under the attribute that uses it.
            const std::string what = e.what(), prefix = src_.file + ": ";
            throw input_error(src_.file, element,
                              what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what);
        }
    }

    /// Any other attribute (the specification's custom ones, such as `_ID`): not
    /// rendered, but its accessor must exist and its count sets or must match the
    /// instance count like the transforms'.
    void check_other(const std::string& name) {
        const std::string element = element_ + "." + name;
        take_count(element,
                   src_.model.accessors[size_t(accessor_index(element, attributes_.Get(name)))].count);
    }

    size_t count() const { return count_.value_or(0); }

    /// Unit quaternion k of `q`, renormalized; an error if it is far from unit length.
    Mat4 rotation(const std::vector<double>& q, size_t k) const {
        const double* r = &q[4 * k];
        const double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
        if (!(std::abs(len - 1.0) <= kUnitTolerance))
            throw input_error(src_.file, element_ + "." + kRotation.name,
                              "instance " + std::to_string(k) + " is not a unit quaternion (length " +
                                  std::to_string(len) + ")");
        return Mat4::rotate_quaternion(r[0] / len, r[1] / len, r[2] / len, r[3] / len);
    }

   private:
    int accessor_index(const std::string& element, const tinygltf::Value& v) const {
        if (!v.IsInt()) throw input_error(src_.file, element, "must be an accessor index");
        const int index = v.GetNumberAsInt();
        if (index < 0 || size_t(index) >= src_.model.accessors.size())
            throw input_error(src_.file, element, "accessor " + std::to_string(index) + " does not exist");
        return index;
    }

    /// All the node's attributes give one value per instance (the specification's "must").
    void take_count(const std::string& element, size_t count) {
        if (count == 0) throw input_error(src_.file, element, "has no instances (count 0)");
        if (count_ && count != *count_)
            throw input_error(src_.file, element,
                              "has " + std::to_string(count) + " instances, another attribute has " +
                                  std::to_string(*count_));
        count_ = count;
    }

    const Source& src_;
    const tinygltf::Value& attributes_;
    std::string element_;
    std::optional<size_t> count_;
};

}  // namespace

std::optional<std::vector<Mat4>> gpu_instances(const Source& src, const tinygltf::Node& node,
                                               const std::string& node_element) {
    const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == node.extensions.end()) return std::nullopt;
    const std::string element = node_element + ".extensions.EXT_mesh_gpu_instancing";
    const char* none = "has no attributes";
    // tinygltf drops an empty JSON object: missing and empty attributes look alike.
    if (!ext->second.IsObject() || !ext->second.Has("attributes"))
        throw input_error(src.file, element + ".attributes", none);
    const tinygltf::Value& attributes = ext->second.Get("attributes");
    if (!attributes.IsObject()) throw input_error(src.file, element + ".attributes", "is not an object");
    InstancingReader reader(src, attributes, element + ".attributes");
    const std::vector<double> t = reader.read(kTranslation), r = reader.read(kRotation),
                              s = reader.read(kScale);
    // Every attribute is optional: a node with only custom ones draws its count of
    // instances at the identity (each at the node's own transform).
    for (const std::string& name : attributes.Keys())
        if (name != kTranslation.name && name != kRotation.name && name != kScale.name)
            reader.check_other(name);
    if (reader.count() == 0) throw input_error(src.file, element + ".attributes", none);
    std::vector<Mat4> out(reader.count());
    for (size_t k = 0; k < out.size(); ++k) {
        Mat4& m = out[k];
        if (!t.empty()) m = Mat4::translate({t[3 * k], t[3 * k + 1], t[3 * k + 2]});
        if (!r.empty()) m = m * reader.rotation(r, k);
        if (!s.empty()) m = m * Mat4::scale({s[3 * k], s[3 * k + 1], s[3 * k + 2]});
    }
    return out;
}

}  // namespace sahara::gltf
