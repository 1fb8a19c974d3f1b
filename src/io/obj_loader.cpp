// Wavefront OBJ + MTL loading on top of tinyobjloader. tinyobjloader only
// tokenises here (triangulate = false): polygons are triangulated by
// mesh_utils' ear clipping because its own fan triangulation breaks concave faces.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "base/error.h"
#include "base/log.h"
#include "io/files.h"
#include "io/image_io.h"
#include "io/mesh_utils.h"
#include "io/model_loader.h"
#include "io/obj_material.h"
#include "io/obj_text.h"

namespace sahara {

namespace {

/// First line of a multi-line library message, trimmed to a sane length.
std::string first_line(const std::string& text) {
    std::string line = text.substr(0, text.find('\n'));
    if (line.size() > 200) line = line.substr(0, 200) + "...";
    return line;
}

/// Paths written in .obj/.mtl files: Windows separators become '/', a leading "./" goes.
std::filesystem::path portable_path(std::string name) {
    for (char& c : name)
        if (c == '\\') c = '/';
    while (name.rfind("./", 0) == 0) name.erase(0, 2);
    return std::filesystem::path(name);
}

/// Opens the .mtl files named by `mtllib` relative to the .obj (with Windows
/// separators tolerated); a missing one is a warning. Remembers the folder of
/// the first one read: MTL texture paths are relative to it. Reports every
/// file as not loaded: tinyobjloader stops at the first file of an `mtllib`
/// line that loads, and all of them are wanted (each is read once).
class MtlFileReader : public tinyobj::MaterialReader {
   public:
    explicit MtlFileReader(const std::filesystem::path& obj_file)
        : obj_file_(obj_file), dir_(obj_file.parent_path()) {}

    bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* names, std::string* warn, std::string* err) override {
        const std::filesystem::path path = obj_file_.parent_path() / portable_path(name);
        if (std::find(files_.begin(), files_.end(), path) != files_.end()) return false;
        std::optional<std::string> text;
        try {
            text = read_file(path);
        } catch (const InputError&) {  // missing or unreadable: the model still loads
        }
        if (!text) {
            log_warning(path.string() + ": material library not found (mtllib of " +
                        obj_file_.filename().string() + "), using the default material");
            return false;
        }
        if (!found_) dir_ = path.parent_path();
        found_ = true;
        files_.push_back(path);
        std::istringstream in(obj::prepare_mtl_text(*text));
        tinyobj::LoadMtl(names, materials, &in, warn, err);
        return false;
    }

    const std::filesystem::path& texture_dir() const { return dir_; }
    /// The .mtl files read, in order.
    const std::vector<std::filesystem::path>& files() const { return files_; }

   private:
    std::filesystem::path obj_file_, dir_;
    std::vector<std::filesystem::path> files_;
    bool found_ = false;
};

/// True if each corner turns the same way about the quad's Newell normal (a
/// non-planar quad is judged in that plane).
bool is_convex_quad(const std::vector<Vec3>& q) {
    const Vec3d n = newell_normal(q);
    if (!(length_squared(n) > 0.0)) return false;
    for (size_t i = 0; i < 4; ++i) {
        const Vec3d a(q[i]), b(q[(i + 1) % 4]), c(q[(i + 2) % 4]);
        if (!(dot(cross(b - a, c - b), n) > 0.0)) return false;
    }
    return true;
}

/// Rejects NaN/Inf in v, vn and vt, and NaN/Inf/negative vertex colours
/// (1-based element numbers as in the file).
void validate_attributes(const std::string& file, const tinyobj::attrib_t& attrib) {
    const std::pair<const std::vector<tinyobj::real_t>*, const char*> lists[] = {
        {&attrib.vertices, "v"}, {&attrib.normals, "vn"}, {&attrib.texcoords, "vt"}};
    for (const auto& [values, name] : lists) {
        const size_t stride = std::string(name) == "vt" ? 2 : 3;
        for (size_t i = 0; i < values->size(); ++i)
            if (!std::isfinite(float((*values)[i])))  // read in double, stored in float
                throw input_error(file, std::string(name) + " #" + std::to_string(i / stride + 1),
                                  "coordinate is not a finite number");
    }
    for (size_t i = 0; i < attrib.colors.size(); ++i) {
        const tinyobj::real_t c = attrib.colors[i];
        if (!std::isfinite(float(c)) || c < 0)
            throw input_error(file, "v #" + std::to_string(i / 3 + 1),
                              c < 0 ? "colour is negative" : "colour is not a finite number");
    }
}

/// OBJ vertex colours as linear RGB, in place. Writers store display colours
/// (sRGB-encoded, from 8-bit values): 0-1, or 0-255 by some tools, which any
/// component above 1 gives away.
void decode_vertex_colors(const std::string& file, std::vector<tinyobj::real_t>& colors) {
    const bool bytes = std::any_of(colors.begin(), colors.end(), [](tinyobj::real_t c) { return c > 1; });
    if (bytes) log_info(file + ": vertex colours above 1, read as 0-255");
    for (tinyobj::real_t& c : colors)
        c = tinyobj::real_t(srgb_decode(std::min(float(bytes ? c / 255 : c), 1.0f)));
}

/// Identifies an output vertex: OBJ position/texcoord/normal indices. In a
/// group with normals, faces without them store -(face + 2) as normal index:
/// their vertices carry that face's own flat normal. A group without normals
/// shares its vertices between faces.
struct VertexKey {
    int v, vt, vn;
    bool operator==(const VertexKey&) const = default;
};
struct VertexKeyHash {
    size_t operator()(const VertexKey& k) const {
        return std::hash<uint64_t>()((uint64_t(uint32_t(k.v)) << 32) ^
                                     (uint64_t(uint32_t(k.vt)) * 0x9E3779B1u) ^
                                     (uint64_t(uint32_t(k.vn)) << 16));
    }
};

/// Turns one tinyobjloader shape (an OBJ group) into an indexed TriangleMesh.
class ObjShapeBuilder {
   public:
    ObjShapeBuilder(const std::string& file, const tinyobj::attrib_t& attrib, LoadedModel& model,
                    int& default_material, bool fan_split)
        : file_(file),
          attrib_(attrib),
          model_(model),
          default_material_(default_material),
          fan_split_(fan_split) {}

    TriangleMesh build(const tinyobj::shape_t& shape, size_t& face_number) {
        const tinyobj::mesh_t& m = shape.mesh;
        size_t total = 0;
        for (unsigned char n : m.num_face_vertices) total += n;
        if (total != m.indices.size())
            throw input_error(file_, "group '" + shape.name + "'", "a face has more than 255 vertices");
        mesh_ = TriangleMesh{};
        mesh_.name = file_ + ": group '" + shape.name + "'";
        map_.clear();
        with_normals_ =
            std::any_of(m.indices.begin(), m.indices.end(), [](auto& i) { return i.normal_index >= 0; });
        with_uvs_ =
            std::any_of(m.indices.begin(), m.indices.end(), [](auto& i) { return i.texcoord_index >= 0; });
        size_t offset = 0;
        for (size_t f = 0; f < m.num_face_vertices.size(); ++f) {
            ++face_number;
            const size_t n = m.num_face_vertices[f];
            add_face(std::span(m.indices).subspan(offset, n),
                     f < m.material_ids.size() ? m.material_ids[f] : -1, face_number);
            offset += n;
        }
        return std::move(mesh_);
    }

   private:
    void check(int index, size_t count, const char* kind, size_t face_number) const {
        if (index >= 0 && size_t(index) < count) return;
        throw input_error(
            file_, "face " + std::to_string(face_number),
            std::string(kind) + " index out of range (the file has " + std::to_string(count) + ")");
    }

    void add_face(std::span<const tinyobj::index_t> face, int material_id, size_t face_number) {
        if (face.size() < 3) return;  // points and lines are not surfaces
        const size_t nv = attrib_.vertices.size() / 3, nn = attrib_.normals.size() / 3,
                     nt = attrib_.texcoords.size() / 2;
        poly_.clear();
        bool face_normals = true;
        for (const tinyobj::index_t& i : face) {
            check(i.vertex_index, nv, "vertex", face_number);
            if (i.texcoord_index != -1) check(i.texcoord_index, nt, "texture coordinate", face_number);
            if (i.normal_index != -1) check(i.normal_index, nn, "normal", face_number);
            face_normals = face_normals && i.normal_index >= 0;
            const tinyobj::real_t* p = &attrib_.vertices[3 * size_t(i.vertex_index)];
            poly_.emplace_back(float(p[0]), float(p[1]), float(p[2]));
        }
        Vec3 flat(0.0f);
        if (with_normals_ && !face_normals) {
            const Vec3d n = newell_normal(poly_);
            if (length_squared(n) > 0.0) flat = Vec3(normalize(n));
        }
        local_.clear();
        if (fan_split_)
            for (uint32_t k = 1; k + 1 < poly_.size(); ++k) local_.insert(local_.end(), {0, k, k + 1});
        else if (poly_.size() == 4 && is_convex_quad(poly_))
            local_ = {0, 1, 2, 0, 2, 3};  // the v0-v2 diagonal, as Blender, assimp and tinyobjloader split
        else
            triangulate_polygon(poly_, local_);
        const uint32_t material = material_index(material_id);
        for (size_t t = 0; t < local_.size(); t += 3) {
            for (size_t k = 0; k < 3; ++k) {
                const tinyobj::index_t& i = face[local_[t + k]];
                const int vn = face_normals ? i.normal_index : with_normals_ ? -int(face_number) - 1 : -1;
                const VertexKey key{i.vertex_index, i.texcoord_index, vn};
                mesh_.indices.push_back(vertex(key, poly_[local_[t + k]], flat));
            }
            mesh_.material_ids.push_back(material);
        }
    }

    uint32_t vertex(const VertexKey& key, const Vec3& position, const Vec3& flat) {
        auto [it, inserted] = map_.try_emplace(key, uint32_t(mesh_.positions.size()));
        if (!inserted) return it->second;
        mesh_.positions.push_back(position);
        if (with_uvs_) {
            Vec2 uv{0, 0};
            if (key.vt >= 0)
                uv = {float(attrib_.texcoords[2 * size_t(key.vt)]),
                      float(attrib_.texcoords[2 * size_t(key.vt) + 1])};
            mesh_.uvs.push_back(uv);
        }
        if (with_normals_) {
            Vec3 n = flat;
            if (key.vn >= 0) {
                const tinyobj::real_t* v = &attrib_.normals[3 * size_t(key.vn)];
                n = Vec3(float(v[0]), float(v[1]), float(v[2]));
                if (length_squared(n) > 0.0f) n = normalize(n);
            }
            mesh_.normals.push_back(n);
        }
        if (!attrib_.colors.empty()) {
            const tinyobj::real_t* c = &attrib_.colors[3 * size_t(key.v)];
            mesh_.colors.emplace_back(float(c[0]), float(c[1]), float(c[2]));
        }
        return it->second;
    }

    /// usemtl of an unknown name (or none) gives -1: the shared default material.
    uint32_t material_index(int id) {
        if (id >= 0 && size_t(id) < model_.materials.size()) return uint32_t(id);
        if (default_material_ < 0) {
            model_.materials.push_back(default_material());
            default_material_ = int(model_.materials.size()) - 1;
        }
        return uint32_t(default_material_);
    }

    const std::string& file_;
    const tinyobj::attrib_t& attrib_;
    LoadedModel& model_;
    int& default_material_;
    const bool fan_split_;
    TriangleMesh mesh_;
    std::unordered_map<VertexKey, uint32_t, VertexKeyHash> map_;
    bool with_normals_ = false, with_uvs_ = false;
    std::vector<Vec3> poly_;
    std::vector<uint32_t> local_;
};

/// One mesh per group; per-triangle material ids collapse to `material` when uniform.
void build_obj_meshes(const std::string& file, const tinyobj::attrib_t& attrib,
                      const std::vector<tinyobj::shape_t>& shapes, bool fan_split, LoadedModel& model) {
    int default_material = -1;
    size_t face_number = 0;
    ObjShapeBuilder builder(file, attrib, model, default_material, fan_split);
    for (const tinyobj::shape_t& shape : shapes) {
        TriangleMesh mesh = builder.build(shape, face_number);
        if (mesh.indices.empty()) continue;
        const auto& ids = mesh.material_ids;
        if (std::all_of(ids.begin(), ids.end(), [&](uint32_t id) { return id == ids.front(); })) {
            mesh.material = ids.front();
            mesh.material_ids.clear();
        }
        if (!mesh.colors.empty())  // so that `sahara info` says the colours are used
            for (uint32_t id :
                 mesh.material_ids.empty() ? std::vector<uint32_t>{mesh.material} : mesh.material_ids)
                model.materials[id].vertex_colors = true;
        model.meshes.push_back(std::move(mesh));
    }
}

/// Where a model far from the origin is recentred before its positions round to
/// float: the centre of its vertices' box, or zero for a model within 1024 of the
/// origin (float keeps ~1e-4 there, and files near the origin load unchanged).
Vec3d far_model_centre(const std::vector<tinyobj::real_t>& v) {
    Vec3d lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double reach = 0;
    for (size_t i = 0; i + 2 < v.size(); i += 3) {
        const Vec3d p{double(v[i]), double(v[i + 1]), double(v[i + 2])};
        lo = min(lo, p);
        hi = max(hi, p);
        reach = std::max({reach, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    }
    return reach > 1024.0 ? (lo + hi) * 0.5 : Vec3d(0.0);
}

/// tinyobjloader's warnings, one line each; a missing .mtl is reported by MtlFileReader, and
/// without materials (the BVH tools) unknown usemtl names are expected.
void log_obj_warnings(const std::string& file, const std::string& warn, bool materials) {
    std::istringstream warnings(obj::decode_material_name(warn));
    for (std::string line; std::getline(warnings, line);) {
        // tinyobjloader ends its "Degenerated face found" with a stray "." line.
        if (line.empty() || line == "." || line.find("Failed to load material file") != std::string::npos)
            continue;
        if (line == "Degenerated face found") line = "a face with fewer than 3 vertices is skipped";
        if (!materials && line.find("not found in .mtl") != std::string::npos) continue;
        log_warning(file + ": " + line);
    }
}

}  // namespace

LoadedModel load_obj(const std::filesystem::path& file, const Mat4& world_from_model) {
    return load_obj(file, world_from_model, ObjReadOptions{});
}

LoadedModel load_obj(const std::filesystem::path& file, const Mat4& world_from_model,
                     const ObjReadOptions& options) {
    const std::string text = read_file(file);
    obj::check_encoding(file.string(), text);
    const std::string prepared =
        obj::prepare_obj_text(text.rfind("\xEF\xBB\xBF", 0) == 0 ? text.substr(3) : text,  // UTF-8 BOM
                              file.parent_path());
    obj::check_obj_numbers(file.string(), prepared);
    std::istringstream stream(prepared);
    MtlFileReader mtl_reader(file);
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream,
                          options.materials ? &mtl_reader : nullptr,
                          /*triangulate=*/false,
                          /*default_vcols_fallback=*/false))
        throw input_error(file.string(), "", "malformed OBJ: " + first_line(err));
    log_obj_warnings(file.string(), warn, options.materials);
    for (tinyobj::material_t& m : materials) m.name = obj::decode_material_name(m.name);

    LoadedModel model;
    obj::MtlKeys keys;
    for (const std::filesystem::path& mtl : mtl_reader.files())
        for (auto& [name, set] : obj::scan_mtl(mtl.string(), read_file(mtl))) keys[name].merge(set);
    obj::ObjTextures textures(model, mtl_reader.texture_dir());
    for (const tinyobj::material_t& m : materials)
        model.materials.push_back(obj::convert_material(m, keys[m.name], textures));
    validate_attributes(file.string(), attrib);
    decode_vertex_colors(file.string(), attrib.colors);
    // The file's digits were read in double (tinyobjloader's double build): subtract
    // the centre before they become float, and let the transform (double) add it back.
    const Vec3d centre = far_model_centre(attrib.vertices);
    Mat4 placed = world_from_model;
    if (centre != Vec3d(0.0)) {
        for (size_t i = 0; i + 2 < attrib.vertices.size(); i += 3)
            for (size_t k = 0; k < 3; ++k) attrib.vertices[i + k] -= centre[int(k)];
        placed = world_from_model * Mat4::translate(centre);
    }
    build_obj_meshes(file.string(), attrib, shapes, options.fan_split, model);
    if (model.meshes.empty()) throw input_error(file.string(), "", "no faces (is this an OBJ file?)");
    if (model.materials.empty()) model.materials.push_back(default_material());

    for (TriangleMesh& mesh : model.meshes) {
        transform_mesh(mesh, placed);
        if (!options.keep_degenerate) model.dropped_degenerate += remove_degenerate(mesh);
    }
    std::erase_if(model.meshes, [](const TriangleMesh& m) { return m.indices.empty(); });
    if (model.dropped_degenerate > 0)
        log_info(file.string() + ": dropped " + std::to_string(model.dropped_degenerate) +
                 " zero-area triangles");
    return model;
}

}  // namespace sahara
