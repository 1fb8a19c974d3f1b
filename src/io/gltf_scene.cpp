// The glTF node hierarchy: transforms, mesh instances, cameras and
// KHR_lights_punctual lights, all brought to sahara's world space.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <tuple>

#include "base/error.h"
#include "base/log.h"
#include "io/gltf_detail.h"
#include "io/mesh_utils.h"

namespace sahara::gltf {

namespace {

std::string indexed(const char* kind, size_t i) { return std::string(kind) + "[" + std::to_string(i) + "]"; }

/// Builds world-space meshes, cameras and lights from the node tree.
class SceneBuilder {
   public:
    SceneBuilder(const Source& src, const Mat4& world_from_model, LoadedModel& out)
        : src_(src), m_(src.model), world_from_model_(world_from_model), out_(out), materials_(src, out) {}

    /// Node world matrices first (skins need their joints' matrices), then the meshes:
    /// a mesh that several unskinned nodes draw (with the same morph weights) is
    /// loaded once, as a prototype, and each node places an instance of it. A node
    /// with EXT_mesh_gpu_instancing always places instances: its count is the
    /// author's promise of many copies, which copying would multiply in memory.
    void build(SharedMeshes shared) {
        for (int root : roots()) walk(root);
        std::map<InstanceKey, int> uses;
        for (const auto& [node, world] : drawn_)
            if (auto key = instance_key(node); key && shared == SharedMeshes::instance) ++uses[*key];
        for (const auto& [node, world] : drawn_) {
            const std::optional<InstanceKey> key = instance_key(node);
            if (auto it = gpu_instances_.find(node); it != gpu_instances_.end())
                add_gpu_instances(node, key, world, it->second);
            else if (!(key && uses[*key] > 1 && add_instance(*key, world)))
                add_mesh(node, world);
        }
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
            node_world_[index] = world;
            if (node.mesh >= 0) drawn_.emplace_back(index, world);
            if (auto local = gpu_instances(src_, node, element); local && node.mesh >= 0)
                gpu_instances_[index] = std::move(*local);
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

    /// Default morph weights: the node's, else the mesh's, else zero (glTF 2.0, "Morph Targets").
    std::vector<double> morph_weights(const tinygltf::Node& node, const tinygltf::Mesh& mesh,
                                      const std::string& element) const {
        const std::vector<double>& w = node.weights.empty() ? mesh.weights : node.weights;
        for (double d : w)
            if (!std::isfinite(d))
                throw input_error(src_.file, element + ".weights", "is not a finite number");
        return w;
    }

    using InstanceKey = std::pair<int, std::vector<double>>;  ///< mesh, morph weights

    /// What makes two nodes draw the same triangles; none for skinned nodes (posed
    /// each on its own) and for nodes whose mesh does not exist (add_mesh says so).
    std::optional<InstanceKey> instance_key(int node_index) const {
        const tinygltf::Node& node = m_.nodes[size_t(node_index)];
        if (node.skin >= 0 || size_t(node.mesh) >= m_.meshes.size()) return std::nullopt;
        return InstanceKey{node.mesh, morph_weights(node, m_.meshes[size_t(node.mesh)],
                                                    indexed("nodes", size_t(node_index)))};
    }

    /// The primitive's triangles in the mesh's space (read once per key).
    const std::optional<TriangleMesh>& cached_primitive(int mesh, size_t p,
                                                        const std::vector<double>& weights) {
        const auto key = std::make_tuple(mesh, int(p), weights);
        if (!primitives_.count(key)) primitives_[key] = primitive(size_t(mesh), p, weights);
        return primitives_[key];
    }

    /// Places the prototype of `key` (made at its first use) with `world`; false when the
    /// transform cannot be inverted (the caller then copies the triangles).
    bool add_instance(const InstanceKey& key, const Mat4& world) {
        const double det = world.determinant3();
        if (!(std::isfinite(det) && det != 0.0)) return false;
        auto it = prototype_of_.find(key);
        if (it == prototype_of_.end()) {
            const auto [mesh, weights] = key;
            PrototypeDesc proto;
            proto.name = src_.file + ": " + indexed("meshes", size_t(mesh));
            for (size_t p = 0; p < m_.meshes[size_t(mesh)].primitives.size(); ++p) {
                const std::optional<TriangleMesh>& cached = cached_primitive(mesh, p, weights);
                if (!cached) continue;
                TriangleMesh copy = *cached;
                copy.name = proto.name + "." + indexed("primitives", p);
                out_.dropped_degenerate += remove_degenerate(copy);
                if (copy.indices.empty()) continue;
                proto.meshes.push_back(uint32_t(out_.meshes.size()));
                out_.meshes.push_back(std::move(copy));
            }
            int index = -1;
            if (!proto.meshes.empty()) {
                index = int(out_.prototypes.size());
                out_.prototypes.push_back(std::move(proto));
            }
            it = prototype_of_.emplace(key, index).first;
        }
        if (it->second >= 0) out_.instances.push_back({uint32_t(it->second), world});
        return true;
    }

    /// One instance per EXT_mesh_gpu_instancing entry, at the node's world matrix x the
    /// entry's; entries whose matrix cannot be inverted are copied, like add_instance's
    /// callers do. A skinned node ignores its own transform, so its instances would
    /// coincide: it is drawn once.
    void add_gpu_instances(int node_index, const std::optional<InstanceKey>& key, const Mat4& world,
                           const std::vector<Mat4>& local) {
        if (!key) {
            if (m_.nodes[size_t(node_index)].skin >= 0)
                log_warning(src_.file + ": " + indexed("nodes", size_t(node_index)) +
                            ": EXT_mesh_gpu_instancing on a skinned node, drawn once");
            add_mesh(node_index, world);
            return;
        }
        for (const Mat4& m : local)
            if (const Mat4 w = world * m; !add_instance(*key, w)) add_mesh(node_index, w);
    }

    void add_mesh(int node_index, const Mat4& world) {
        const tinygltf::Node& node = m_.nodes[size_t(node_index)];
        const std::string node_element = indexed("nodes", size_t(node_index));
        const int mesh = node.mesh;
        if (size_t(mesh) >= m_.meshes.size())
            throw input_error(src_.file, node_element + ".mesh",
                              "mesh " + std::to_string(mesh) + " does not exist");
        const tinygltf::Mesh& gmesh = m_.meshes[size_t(mesh)];
        const std::vector<double> weights = morph_weights(node, gmesh, node_element);
        const std::optional<std::vector<Mat4>> joints = joint_matrices(node, node_element);
        for (size_t p = 0; p < gmesh.primitives.size(); ++p) {
            const std::optional<TriangleMesh>& cached = cached_primitive(mesh, p, weights);
            if (!cached) continue;
            TriangleMesh instance = *cached;
            instance.name = src_.file + ": " + node_element + " " + indexed("meshes", size_t(mesh)) + "." +
                            indexed("primitives", p);
            if (joints) {  // a skinned mesh ignores its node's transform (glTF 2.0, "Skins")
                apply_skin(src_, gmesh.primitives[p],
                           indexed("meshes", size_t(mesh)) + "." + indexed("primitives", p), *joints,
                           instance);
            } else {
                transform_mesh(instance, world);
            }
            out_.dropped_degenerate += remove_degenerate(instance);
            if (!instance.indices.empty()) out_.meshes.push_back(std::move(instance));
        }
    }

    std::optional<TriangleMesh> primitive(size_t mesh, size_t p, const std::vector<double>& weights) {
        std::optional<TriangleMesh> out = read_primitive(src_, mesh, p, weights);
        if (!out) return out;
        const tinygltf::Primitive& prim = m_.meshes[mesh].primitives[p];
        const std::string element = indexed("meshes", mesh) + "." + indexed("primitives", p);
        const int material = variant_material(src_, prim, element);
        const std::string user = material == prim.material ? element + ".material"
                                                           : element + ".extensions.KHR_materials_variants";
        out->material = materials_.get(material, user, !out->colors.empty());
        mark_vertex_alpha(*out, material);
        return out;
    }

    /// COLOR_0's alpha scales a MASK or BLEND material's alpha (the specification's
    /// base colour is factor x texture x COLOR_0, alpha included); OPAQUE ignores it.
    void mark_vertex_alpha(const TriangleMesh& mesh, int material) {
        if (material < 0) return;  // the default material is OPAQUE
        const std::string& mode = m_.materials[size_t(material)].alphaMode;
        if (mode.empty() || mode == "OPAQUE") return;
        if (std::any_of(mesh.color_alphas.begin(), mesh.color_alphas.end(), [](float a) { return a < 1.0f; }))
            out_.materials[mesh.material].vertex_alpha = true;
    }

    /// For a skinned node: world_from_model x each joint's world matrix x its inverse
    /// bind matrix, posing the mesh as the nodes stand (the bind pose unless the file
    /// stores another); nothing for unskinned nodes.
    std::optional<std::vector<Mat4>> joint_matrices(const tinygltf::Node& node, const std::string& element) {
        if (node.skin < 0) return std::nullopt;
        if (size_t(node.skin) >= m_.skins.size())
            throw input_error(src_.file, element + ".skin",
                              "skin " + std::to_string(node.skin) + " does not exist");
        const tinygltf::Skin& skin = m_.skins[size_t(node.skin)];
        const std::string skin_element = indexed("skins", size_t(node.skin));
        std::vector<double> ibm;
        if (skin.inverseBindMatrices >= 0)
            ibm = read_accessor(src_, skin.inverseBindMatrices, skin_element + ".inverseBindMatrices", 16);
        if (!ibm.empty() && ibm.size() != 16 * skin.joints.size())
            throw input_error(src_.file, skin_element + ".inverseBindMatrices", "needs one matrix per joint");
        std::vector<Mat4> out;
        for (size_t k = 0; k < skin.joints.size(); ++k) {
            auto it = node_world_.find(skin.joints[k]);
            if (it == node_world_.end()) {
                log_warning(src_.file + ": " + skin_element + ": joint " + std::to_string(skin.joints[k]) +
                            " is not in the scene, mesh drawn unskinned");
                return std::nullopt;
            }
            Mat4 inverse_bind;
            for (size_t r = 0; r < 4 && !ibm.empty(); ++r)
                for (size_t c = 0; c < 4; ++c)
                    inverse_bind.m[r][c] = ibm[16 * k + c * 4 + r];  // column-major
            out.push_back(it->second * inverse_bind);
        }
        return out;
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
    std::map<int, Mat4> node_world_;                  ///< world matrix of every node in the scene
    std::vector<std::pair<int, Mat4>> drawn_;         ///< nodes with a mesh, in walk order
    std::map<int, std::vector<Mat4>> gpu_instances_;  ///< EXT_mesh_gpu_instancing matrices per node
    std::map<std::tuple<int, int, std::vector<double>>, std::optional<TriangleMesh>> primitives_;
    std::map<InstanceKey, int> prototype_of_;  ///< prototype index per shared mesh; -1: no triangles
};

}  // namespace

void build_scene(const Source& src, const Mat4& world_from_model, SharedMeshes shared, LoadedModel& out) {
    SceneBuilder(src, world_from_model, out).build(shared);
}

}  // namespace sahara::gltf
