// One glTF primitive's vertex data (POSITION, NORMAL, TEXCOORD_0/1, COLOR_0,
// TANGENT) with its morph targets applied at their default weights, and the
// linear blend skinning that poses a skinned primitive.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "base/error.h"
#include "base/log.h"
#include "io/gltf_detail.h"

namespace sahara::gltf {

namespace {

std::string indexed(const char* kind, size_t i) { return std::string(kind) + "[" + std::to_string(i) + "]"; }

/// Expands a strip or fan into a triangle list (glTF 2.0 spec, section 3.7.2.1:
/// strip triangle i is {i, i+1+i%2, i+2-i%2}; fan triangle i is {i+1, i+2, 0}).
std::vector<uint32_t> to_triangle_list(const std::vector<uint32_t>& idx, int mode) {
    if (mode == TINYGLTF_MODE_TRIANGLES)
        return std::vector<uint32_t>(idx.begin(), idx.begin() + std::ptrdiff_t(idx.size() / 3 * 3));
    std::vector<uint32_t> out;
    for (size_t i = 0; i + 2 < idx.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
            out.insert(out.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
        else
            out.insert(out.end(), {idx[i + 1], idx[i + 2], idx[0]});
    }
    return out;
}

/// Number of components of accessor `index`'s type (VEC3: 3), 0 if it does not exist.
int components_of(const Source& src, int index) {
    if (index < 0 || size_t(index) >= src.model.accessors.size()) return 0;
    const int n = tinygltf::GetNumComponentsInType(uint32_t(src.model.accessors[size_t(index)].type));
    return n < 0 ? 0 : n;
}

/// The vertex attributes of one primitive, read in double precision so that
/// morph deltas add up before the conversion to float.
class PrimitiveReader {
   public:
    PrimitiveReader(const Source& src, const tinygltf::Primitive& prim, std::string element)
        : src_(src), prim_(prim), element_(std::move(element)) {}

    TriangleMesh read(const std::vector<double>& weights) {
        pos_ = read_accessor(src_, prim_.attributes.at("POSITION"), element_ + ".attributes.POSITION", 3);
        n_ = pos_.size() / 3;
        nrm_ = optional_attribute(prim_.attributes, "NORMAL", element_ + ".attributes", 3);
        tan_ = optional_attribute(prim_.attributes, "TANGENT", element_ + ".attributes", 4);
        check_tangent_signs();
        apply_morph_targets(weights);
        TriangleMesh out;
        for (size_t i = 0; i < n_; ++i) out.positions.emplace_back(vec3(pos_, 3, i));
        for (size_t i = 0; i < nrm_.size() / 3; ++i) out.normals.push_back(unit(vec3(nrm_, 3, i)));
        for (size_t i = 0; i < tan_.size() / 4; ++i) {
            const Vec3 t = unit(vec3(tan_, 4, i));
            out.tangents.push_back({t.x, t.y, t.z, tan_[4 * i + 3] < 0.0 ? -1.0f : 1.0f});
        }
        read_uvs(out);
        read_colors(out);
        out.indices = to_triangle_list(indices(), prim_.mode);
        return out;
    }

   private:
    static Vec3 vec3(const std::vector<double>& v, size_t stride, size_t i) {
        return {float(v[stride * i]), float(v[stride * i + 1]), float(v[stride * i + 2])};
    }
    static Vec3 unit(const Vec3& v) { return length_squared(v) > 0.0f ? normalize(v) : v; }

    /// The named attribute of `attrs` (empty if absent), checked to have one element per vertex.
    std::vector<double> optional_attribute(const std::map<std::string, int>& attrs, const std::string& name,
                                           const std::string& where, int components) const {
        auto it = attrs.find(name);
        if (it == attrs.end()) return {};
        const std::string element = where + "." + name;
        std::vector<double> v = read_accessor(src_, it->second, element, components);
        if (v.size() != n_ * size_t(components))
            throw input_error(src_.file, element,
                              "has " + std::to_string(v.size() / size_t(components)) +
                                  " elements, POSITION has " + std::to_string(n_));
        return v;
    }

    /// TANGENT's w is the bitangent's sign: glTF requires +1 or -1 (read_accessor
    /// has already refused non-finite values).
    void check_tangent_signs() const {
        for (size_t i = 0; i < tan_.size() / 4; ++i) {
            const double w = tan_[4 * i + 3];
            if (std::abs(std::abs(w) - 1.0) > 1e-3)
                throw input_error(
                    src_.file, element_ + ".attributes.TANGENT",
                    "element " + std::to_string(i) + " has w = " + std::to_string(w) + ", must be 1 or -1");
        }
    }

    /// Each target adds weight x its POSITION, NORMAL and TANGENT (xyz) deltas.
    void apply_morph_targets(const std::vector<double>& weights) {
        for (size_t t = 0; t < prim_.targets.size() && t < weights.size(); ++t) {
            if (weights[t] == 0.0) continue;
            const std::string where = element_ + "." + indexed("targets", t);
            const auto add = [&](std::vector<double>& base, const char* name, int stride) {
                const std::vector<double> d = optional_attribute(prim_.targets[t], name, where, 3);
                if (base.empty()) return;
                for (size_t i = 0; i < d.size() / 3; ++i)
                    for (size_t c = 0; c < 3; ++c) base[size_t(stride) * i + c] += weights[t] * d[3 * i + c];
            };
            add(pos_, "POSITION", 3);
            add(nrm_, "NORMAL", 3);
            add(tan_, "TANGENT", 4);
        }
    }

    void read_uvs(TriangleMesh& out) const {
        const auto uv0 = optional_attribute(prim_.attributes, "TEXCOORD_0", element_ + ".attributes", 2);
        const auto uv1 = optional_attribute(prim_.attributes, "TEXCOORD_1", element_ + ".attributes", 2);
        // sahara's v = 0 is the image bottom, glTF's the top (scene_desc.h).
        for (size_t i = 0; i < uv0.size() / 2; ++i)
            out.uvs.push_back({float(uv0[2 * i]), 1.0f - float(uv0[2 * i + 1])});
        for (size_t i = 0; i < uv1.size() / 2; ++i)
            out.uvs1.push_back({float(uv1[2 * i]), 1.0f - float(uv1[2 * i + 1])});
    }

    /// COLOR_0: VEC3 or VEC4 of floats or normalized unsigned bytes/shorts, linear.
    void read_colors(TriangleMesh& out) const {
        auto it = prim_.attributes.find("COLOR_0");
        if (it == prim_.attributes.end()) return;
        const std::string element = element_ + ".attributes.COLOR_0";
        const int n = components_of(src_, it->second);
        if (n != 3 && n != 4) throw input_error(src_.file, element, "must be VEC3 or VEC4");
        const tinygltf::Accessor& acc = src_.model.accessors[size_t(it->second)];
        if (acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !acc.normalized)
            throw input_error(src_.file, element, "integer colours must be normalized");
        const std::vector<double> c =
            optional_attribute(prim_.attributes, "COLOR_0", element_ + ".attributes", n);
        for (size_t i = 0; i < n_; ++i) {
            const double* v = &c[size_t(n) * i];
            out.colors.emplace_back(float(std::max(v[0], 0.0)), float(std::max(v[1], 0.0)),
                                    float(std::max(v[2], 0.0)));
            if (n == 4) out.color_alphas.push_back(float(std::clamp(v[3], 0.0, 1.0)));
        }
    }

    std::vector<uint32_t> indices() const {
        std::vector<uint32_t> idx;
        if (prim_.indices < 0) {
            idx.resize(n_);
            std::iota(idx.begin(), idx.end(), 0u);
            return idx;
        }
        idx = read_indices(src_, prim_.indices, element_ + ".indices");
        for (uint32_t i : idx)
            if (i >= n_)
                throw input_error(
                    src_.file, element_ + ".indices",
                    "index " + std::to_string(i) + " out of range (" + std::to_string(n_) + " vertices)");
        return idx;
    }

    const Source& src_;
    const tinygltf::Primitive& prim_;
    std::string element_;
    size_t n_ = 0;
    std::vector<double> pos_, nrm_, tan_;
};

/// Weighted sum of matrices (affine, so the bottom row stays 0 0 0 1 when the weights sum to 1).
Mat4 blend(const std::vector<Mat4>& joints, const double* joint, const double* weight, size_t count) {
    Mat4 r;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) r.m[size_t(a)][size_t(b)] = 0.0;
    for (size_t k = 0; k < count; ++k) {
        if (weight[k] == 0.0) continue;
        const Mat4& j = joints[size_t(joint[k])];
        for (size_t a = 0; a < 4; ++a)
            for (size_t b = 0; b < 4; ++b) r.m[a][b] += weight[k] * j.m[a][b];
    }
    return r;
}

}  // namespace

std::optional<TriangleMesh> read_primitive(const Source& src, size_t mesh, size_t p,
                                           const std::vector<double>& weights) {
    const tinygltf::Primitive& prim = src.model.meshes[mesh].primitives[p];
    const std::string element = indexed("meshes", mesh) + "." + indexed("primitives", p);
    if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
        log_warning(src.file + ": " + element + ": points and lines are not rendered, skipped");
        return std::nullopt;
    }
    if (prim.mode > TINYGLTF_MODE_TRIANGLE_FAN || prim.mode < 0)
        throw input_error(src.file, element + ".mode", "invalid mode " + std::to_string(prim.mode));
    if (!prim.attributes.count("POSITION")) {
        log_warning(src.file + ": " + element + ": no POSITION attribute, skipped");
        return std::nullopt;
    }
    return PrimitiveReader(src, prim, element).read(weights);
}

void apply_skin(const Source& src, const tinygltf::Primitive& prim, const std::string& element,
                const std::vector<Mat4>& joint_matrices, TriangleMesh& mesh) {
    const size_t n = mesh.positions.size();
    std::vector<double> total(n, 0.0);  // vertices without weights stay put
    std::vector<Mat4> sum(n);
    for (int set = 0;; ++set) {
        const std::string js = "JOINTS_" + std::to_string(set), ws = "WEIGHTS_" + std::to_string(set);
        auto j = prim.attributes.find(js), w = prim.attributes.find(ws);
        if (j == prim.attributes.end() || w == prim.attributes.end()) break;
        const auto joints = read_accessor(src, j->second, element + ".attributes." + js, 4);
        const auto weights = read_accessor(src, w->second, element + ".attributes." + ws, 4);
        if (joints.size() != 4 * n || weights.size() != 4 * n)
            throw input_error(src.file, element + ".attributes." + js, "element count differs from POSITION");
        for (size_t i = 0; i < n; ++i) {
            for (size_t k = 0; k < 4; ++k)
                if (weights[4 * i + k] != 0.0 &&
                    !(joints[4 * i + k] >= 0.0 && joints[4 * i + k] < double(joint_matrices.size())))
                    throw input_error(src.file, element + ".attributes." + js,
                                      "joint index " + std::to_string(joints[4 * i + k]) + " out of range");
            const Mat4 m = blend(joint_matrices, &joints[4 * i], &weights[4 * i], 4);
            for (size_t a = 0; a < 4; ++a)
                for (size_t b = 0; b < 4; ++b) sum[i].m[a][b] = (set == 0 ? 0.0 : sum[i].m[a][b]) + m.m[a][b];
            for (size_t k = 0; k < 4; ++k) total[i] += weights[4 * i + k];
        }
    }
    for (size_t i = 0; i < n; ++i) {
        if (!(total[i] > 0.0)) continue;
        Mat4 m = sum[i];
        for (size_t a = 0; a < 4; ++a)
            for (size_t b = 0; b < 4; ++b) m.m[a][b] /= total[i];  // weights should sum to 1; make sure
        mesh.positions[i] = m.apply_point(mesh.positions[i]);
        if (i < mesh.normals.size()) mesh.normals[i] = m.apply_normal(mesh.normals[i]);
        if (i < mesh.tangents.size()) {
            auto& t = mesh.tangents[i];
            Vec3 v = m.apply_vector({t[0], t[1], t[2]});
            if (length_squared(v) > 0.0f) v = normalize(v);
            t = {v.x, v.y, v.z, t[3]};
        }
    }
}

}  // namespace sahara::gltf
