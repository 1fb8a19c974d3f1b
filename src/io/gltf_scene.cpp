// The glTF node hierarchy: transforms, mesh instances, cameras and
// KHR_lights_punctual lights, all brought to sahara's world space.
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include "base/error.h"
#include "base/log.h"
#include "io/gltf_detail.h"
#include "io/mesh_utils.h"

namespace sahara::gltf {

namespace {

std::string indexed(const char* kind, size_t i) { return std::string(kind) + "[" + std::to_string(i) + "]"; }

/// Expands a strip or fan into a triangle list (glTF 2.0 spec, section 3.7.2.1:
/// strip triangle i is {i, i+1+i%2, i+2-i%2}; fan triangle i is {i+1, i+2, 0}).
std::vector<uint32_t> to_triangle_list(const std::vector<uint32_t>& idx, int mode) {
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        std::vector<uint32_t> out(idx.begin(), idx.begin() + std::ptrdiff_t(idx.size() / 3 * 3));
        return out;
    }
    std::vector<uint32_t> out;
    for (size_t i = 0; i + 2 < idx.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
            out.insert(out.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
        else
            out.insert(out.end(), {idx[i + 1], idx[i + 2], idx[0]});
    }
    return out;
}

/// Builds world-space meshes, cameras and lights from the node tree.
class SceneBuilder {
   public:
    SceneBuilder(const Source& src, const Mat4& world_from_model, LoadedModel& out)
        : src_(src), m_(src.model), world_from_model_(world_from_model), out_(out), materials_(src, out) {}

    void build() {
        for (int root : roots()) walk(root);
    }

   private:
    /// Root nodes of the default scene (scene 0 if none is marked; all parentless nodes without scenes).
    std::vector<int> roots() const {
        if (!m_.scenes.empty()) {
            const int s = m_.defaultScene >= 0 ? m_.defaultScene : 0;
            if (size_t(s) >= m_.scenes.size())
                throw input_error(src_.file, "scene", "scene " + std::to_string(s) + " does not exist");
            return m_.scenes[size_t(s)].nodes;
        }
        std::vector<bool> is_child(m_.nodes.size(), false);
        for (const auto& n : m_.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < m_.nodes.size()) is_child[size_t(c)] = true;
        std::vector<int> r;
        for (size_t i = 0; i < m_.nodes.size(); ++i)
            if (!is_child[i]) r.push_back(int(i));
        return r;
    }

    /// Depth-first walk with an explicit stack; a node reached twice means a
    /// cycle or a shared child, both invalid glTF.
    void walk(int root) {
        std::vector<std::pair<int, Mat4>> stack{{root, world_from_model_}};
        visited_.resize(m_.nodes.size(), false);
        while (!stack.empty()) {
            auto [index, parent] = stack.back();
            stack.pop_back();
            if (index < 0 || size_t(index) >= m_.nodes.size())
                throw input_error(src_.file, "nodes", "node " + std::to_string(index) + " does not exist");
            const std::string element = indexed("nodes", size_t(index));
            if (visited_[size_t(index)])
                throw input_error(src_.file, element,
                                  "reached twice (cycle or shared child in the node tree)");
            visited_[size_t(index)] = true;
            const tinygltf::Node& node = m_.nodes[size_t(index)];
            const Mat4 world = parent * local_matrix(node, element);
            if (node.mesh >= 0) add_mesh(node.mesh, world, element);
            if (node.camera >= 0) add_camera(node.camera, world, element);
            if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end())
                add_light(it->second, world, element);
            for (int child : node.children) stack.emplace_back(child, world);
        }
    }

    static std::vector<double> checked(const std::vector<double>& v, size_t size, const std::string& element,
                                       const std::string& src_file) {
        if (!v.empty() && v.size() != size)
            throw input_error(src_file, element, "expected " + std::to_string(size) + " numbers");
        for (double d : v)
            if (!std::isfinite(d)) throw input_error(src_file, element, "is not a finite number");
        return v;
    }

    /// `matrix` (column-major) or translation * rotation * scale.
    Mat4 local_matrix(const tinygltf::Node& node, const std::string& element) const {
        const auto matrix = checked(node.matrix, 16, element + ".matrix", src_.file);
        if (!matrix.empty()) {
            Mat4 m;
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) m.m[size_t(r)][size_t(c)] = matrix[size_t(c * 4 + r)];
            return m;
        }
        const auto t = checked(node.translation, 3, element + ".translation", src_.file);
        const auto r = checked(node.rotation, 4, element + ".rotation", src_.file);
        const auto s = checked(node.scale, 3, element + ".scale", src_.file);
        Mat4 result;
        if (!t.empty()) result = Mat4::translate({t[0], t[1], t[2]});
        if (!r.empty()) {
            const double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
            if (len == 0.0) throw input_error(src_.file, element + ".rotation", "is a zero quaternion");
            result = result * Mat4::rotate_quaternion(r[0] / len, r[1] / len, r[2] / len, r[3] / len);
        }
        if (!s.empty()) result = result * Mat4::scale({s[0], s[1], s[2]});
        return result;
    }

    void add_mesh(int mesh, const Mat4& world, const std::string& node_element) {
        if (size_t(mesh) >= m_.meshes.size())
            throw input_error(src_.file, node_element + ".mesh",
                              "mesh " + std::to_string(mesh) + " does not exist");
        const auto& prims = m_.meshes[size_t(mesh)].primitives;
        for (size_t p = 0; p < prims.size(); ++p) {
            const auto key = std::make_pair(mesh, int(p));
            if (!primitives_.count(key)) primitives_[key] = primitive(size_t(mesh), p);
            const std::optional<TriangleMesh>& cached = primitives_[key];
            if (!cached) continue;
            TriangleMesh instance = *cached;
            instance.name = src_.file + ": " + node_element + " " + indexed("meshes", size_t(mesh)) + "." +
                            indexed("primitives", p);
            transform_mesh(instance, world);
            out_.dropped_degenerate += remove_degenerate(instance);
            if (!instance.indices.empty()) out_.meshes.push_back(std::move(instance));
        }
    }

    /// One primitive in model space, or nothing if it is not made of triangles.
    std::optional<TriangleMesh> primitive(size_t mesh, size_t p) {
        const tinygltf::Primitive& prim = m_.meshes[mesh].primitives[p];
        const std::string element = indexed("meshes", mesh) + "." + indexed("primitives", p);
        if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
            log_warning(src_.file + ": " + element + ": points and lines are not rendered, skipped");
            return std::nullopt;
        }
        if (prim.mode > TINYGLTF_MODE_TRIANGLE_FAN || prim.mode < 0)
            throw input_error(src_.file, element + ".mode", "invalid mode " + std::to_string(prim.mode));
        auto pos_it = prim.attributes.find("POSITION");
        if (pos_it == prim.attributes.end()) {
            log_warning(src_.file + ": " + element + ": no POSITION attribute, skipped");
            return std::nullopt;
        }
        TriangleMesh out;
        const std::vector<double> pos =
            read_accessor(src_, pos_it->second, element + ".attributes.POSITION", 3);
        const size_t n = pos.size() / 3;
        for (size_t i = 0; i < n; ++i)
            out.positions.emplace_back(float(pos[3 * i]), float(pos[3 * i + 1]), float(pos[3 * i + 2]));
        if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
            const auto nrm = read_attribute(it->second, element + ".attributes.NORMAL", 3, n);
            for (size_t i = 0; i < n; ++i) {
                const Vec3 v{float(nrm[3 * i]), float(nrm[3 * i + 1]), float(nrm[3 * i + 2])};
                out.normals.push_back(length_squared(v) > 0.0f ? normalize(v) : v);
            }
        }
        const std::string uv_name = "TEXCOORD_" + std::to_string(materials_.texcoord_set(prim.material));
        if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
            const auto uv = read_attribute(it->second, element + ".attributes." + uv_name, 2, n);
            for (size_t i = 0; i < n; ++i)
                out.uvs.push_back({float(uv[2 * i]), 1.0f - float(uv[2 * i + 1])});  // v=0 at bottom
        }
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
            idx = read_indices(src_, prim.indices, element + ".indices");
            for (uint32_t i : idx)
                if (i >= n)
                    throw input_error(
                        src_.file, element + ".indices",
                        "index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
        } else {
            idx.resize(n);
            std::iota(idx.begin(), idx.end(), 0u);
        }
        out.indices = to_triangle_list(idx, prim.mode);
        out.material = materials_.get(prim.material, element + ".material");
        return out;
    }

    std::vector<double> read_attribute(int accessor, const std::string& element, int components,
                                       size_t count) {
        std::vector<double> v = read_accessor(src_, accessor, element, components);
        if (v.size() != count * size_t(components))
            throw input_error(src_.file, element,
                              "has " + std::to_string(v.size() / size_t(components)) +
                                  " elements, POSITION has " + std::to_string(count));
        return v;
    }

    /// Camera looks down its local -Z with +Y up (glTF 2.0 spec, "Cameras").
    void add_camera(int index, const Mat4& world, const std::string& node_element) {
        if (size_t(index) >= m_.cameras.size())
            throw input_error(src_.file, node_element + ".camera",
                              "camera " + std::to_string(index) + " does not exist");
        const tinygltf::Camera& cam = m_.cameras[size_t(index)];
        const Vec3 fwd = world.apply_vector({0, 0, -1}), up = world.apply_vector({0, 1, 0});
        if (length_squared(cross(fwd, up)) == 0.0f) {
            log_warning(src_.file + ": " + node_element + ": camera transform is singular, camera ignored");
            return;
        }
        CameraDesc c;
        c.position = world.apply_point({0, 0, 0});
        c.basis_forward = normalize(fwd);
        c.basis_up = normalize(up - dot(up, c.basis_forward) * c.basis_forward);
        c.basis_right = cross(c.basis_forward, c.basis_up);
        c.has_basis = true;
        c.look_at = c.position + c.basis_forward;
        c.up = c.basis_up;
        if (cam.type == "orthographic") {
            c.orthographic = true;
            c.ortho_height = float(2.0 * cam.orthographic.ymag) * length(up);
        } else {
            if (!(cam.perspective.yfov > 0.0 && cam.perspective.yfov < std::numbers::pi))
                throw input_error(src_.file, indexed("cameras", size_t(index)) + ".perspective.yfov",
                                  "must be between 0 and pi radians");
            c.vfov = float(cam.perspective.yfov * 180.0 / std::numbers::pi);
        }
        out_.cameras.push_back(c);
    }

    /// KHR_lights_punctual: point intensity in candela (used as W/sr), directional in lux.
    void add_light(const tinygltf::Value& ext, const Mat4& world, const std::string& node_element) {
        if (!ext.Has("light") || !ext.Get("light").IsNumber()) return;
        const int index = ext.Get("light").GetNumberAsInt();
        if (index < 0 || size_t(index) >= m_.lights.size())
            throw input_error(src_.file, node_element + ".extensions.KHR_lights_punctual",
                              "light " + std::to_string(index) + " does not exist");
        const tinygltf::Light& l = m_.lights[size_t(index)];
        const std::string element = "KHR_lights_punctual.lights[" + std::to_string(index) + "]";
        Rgb color(1.0f);
        if (l.color.size() == 3) color = Rgb(float(l.color[0]), float(l.color[1]), float(l.color[2]));
        const Rgb power = color * float(l.intensity);
        if (!is_finite(power))
            throw input_error(src_.file, element, "color or intensity is not a finite number");
        LightDesc d;
        if (l.type == "directional") {
            const Vec3 dir = world.apply_vector({0, 0, -1});
            if (length_squared(dir) == 0.0f) return;
            d.type = LightDesc::Type::directional;
            d.direction = normalize(dir);
            d.irradiance = power;
        } else {
            if (l.type == "spot")
                log_warning(src_.file + ": " + element + ": spot light treated as a point light");
            else if (l.type != "point")
                throw input_error(src_.file, element + ".type", "unknown light type '" + l.type + "'");
            d.position = world.apply_point({0, 0, 0});
            d.intensity = power;
        }
        out_.lights.push_back(d);
    }

    const Source& src_;
    const tinygltf::Model& m_;
    Mat4 world_from_model_;
    LoadedModel& out_;
    Materials materials_;
    std::vector<bool> visited_;
    std::map<std::pair<int, int>, std::optional<TriangleMesh>> primitives_;
};

}  // namespace

void build_scene(const Source& src, const Mat4& world_from_model, LoadedModel& out) {
    SceneBuilder(src, world_from_model, out).build();
}

}  // namespace sahara::gltf
