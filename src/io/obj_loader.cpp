// Wavefront OBJ + MTL loading on top of tinyobjloader. tinyobjloader only
// tokenises here (triangulate = false): polygons are triangulated by
// mesh_utils' ear clipping because its own fan triangulation breaks concave faces.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
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
/// the first one read: MTL texture paths are relative to it.
class MtlFileReader : public tinyobj::MaterialReader {
   public:
    explicit MtlFileReader(const std::filesystem::path& obj_file)
        : obj_file_(obj_file), dir_(obj_file.parent_path()) {}

    bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* names, std::string* warn, std::string* err) override {
        const std::filesystem::path path = obj_file_.parent_path() / portable_path(name);
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
        std::istringstream in(*text);
        tinyobj::LoadMtl(names, materials, &in, warn, err);
        return true;
    }

    const std::filesystem::path& texture_dir() const { return dir_; }

   private:
    std::filesystem::path obj_file_, dir_;
    bool found_ = false;
};

/// tinyobjloader reads "nan" and "inf" as 0; sahara rejects them. Numbers in
/// v/vn/vt lines only ever contain digits, signs, '.', 'e' and 'E'.
void reject_non_finite_words(const std::string& file, const std::string& text) {
    size_t counts[3] = {0, 0, 0};
    const char* names[3] = {"v", "vt", "vn"};
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        const std::string_view line(text.data() + pos, end - pos);
        pos = end + 1;
        const size_t start = line.find_first_not_of(" \t");
        if (start == std::string_view::npos || line[start] != 'v') continue;
        int kind = -1;
        const std::string_view rest = line.substr(start);
        if (rest.size() > 1 && (rest[1] == ' ' || rest[1] == '\t'))
            kind = 0;
        else if (rest.size() > 2 && (rest[2] == ' ' || rest[2] == '\t'))
            kind = rest[1] == 't' ? 1 : rest[1] == 'n' ? 2 : -1;
        if (kind < 0) continue;
        ++counts[kind];
        const std::string_view numbers = rest.substr(0, rest.find('#'));  // comments may say anything
        if (numbers.find_first_of("nNiI", kind == 0 ? 1 : 2) != std::string_view::npos)
            throw input_error(file, std::string(names[kind]) + " #" + std::to_string(counts[kind]),
                              "coordinate is not a finite number");
    }
}

/// What a texture is used for decides its decoding.
enum class TexUse { color, alpha };

/// Loads MTL textures once per (file, use) and turns them into TextureDesc.
class ObjTextures {
   public:
    ObjTextures(LoadedModel& model, std::filesystem::path mtl_dir)
        : model_(model), dir_(std::move(mtl_dir)) {}

    /// Index into model.textures, or -1 (with a warning) when the file is missing.
    int get(const std::string& name, const tinyobj::texture_option_t& opt, TexUse use,
            const std::string& what) {
        const std::filesystem::path path = dir_ / portable_path(name);
        const auto key = std::make_pair(path.string(), use);
        if (auto it = cache_.find(key); it != cache_.end()) return it->second;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) {
            log_warning(path.string() + ": " + what +
                        " texture not found, material falls back to its colour");
            return cache_[key] = -1;
        }
        TextureDesc tex;
        tex.path = path.string();
        tex.image = use == TexUse::color ? read_image(path, true) : alpha_from_grey(read_image(path, false));
        tex.wrap_u = tex.wrap_v = opt.clamp ? WrapMode::clamp : WrapMode::repeat;
        tex.uv_offset = {float(opt.origin_offset[0]), float(opt.origin_offset[1])};
        tex.uv_scale = {float(opt.scale[0]), float(opt.scale[1])};
        model_.textures.push_back(std::move(tex));
        return cache_[key] = int(model_.textures.size()) - 1;
    }

   private:
    /// map_d images are usually grey without an alpha channel: then the grey
    /// value is the alpha (MaterialDesc reads a texture's alpha channel).
    static std::shared_ptr<const Image> alpha_from_grey(std::shared_ptr<const Image> img) {
        for (size_t i = 3; i < img->rgba.size(); i += 4)
            if (img->rgba[i] != 1.0f) return img;
        auto out = std::make_shared<Image>(*img);
        for (size_t i = 0; i + 3 < out->rgba.size(); i += 4) out->rgba[i + 3] = out->rgba[i];
        return out;
    }

    LoadedModel& model_;
    std::filesystem::path dir_;
    std::map<std::pair<std::string, TexUse>, int> cache_;
};

Rgb to_rgb(const tinyobj::real_t* c) { return Rgb(float(c[0]), float(c[1]), float(c[2])); }

/// MTL -> MaterialDesc: Kd/map_Kd albedo (the map replaces Kd, as most OBJ
/// viewers do), Ke/map_Ke emission, d/map_d alpha cut-outs.
MaterialDesc convert_material(const tinyobj::material_t& m, ObjTextures& textures) {
    MaterialDesc out;
    out.name = m.name;
    out.albedo.color = to_rgb(m.diffuse);
    if (!m.diffuse_texname.empty()) {
        const int t = textures.get(m.diffuse_texname, m.diffuse_texopt, TexUse::color, "map_Kd of " + m.name);
        if (t >= 0) out.albedo = {ColorSource::Kind::texture, Rgb(1.0f), {}, {}, 1.0f, t};
    }
    const Rgb ke = to_rgb(m.emission);
    int ke_tex = -1;
    if (!m.emissive_texname.empty())
        ke_tex = textures.get(m.emissive_texname, m.emissive_texopt, TexUse::color, "map_Ke of " + m.name);
    if (max_component(ke) > 0.0f || ke_tex >= 0) {
        out.type = MaterialType::emissive;
        out.radiance.color = max_component(ke) > 0.0f ? ke : Rgb(1.0f);
        if (ke_tex >= 0) {
            out.radiance.kind = ColorSource::Kind::texture;
            out.radiance.texture = ke_tex;
        }
    }
    out.alpha = std::clamp(float(m.dissolve), 0.0f, 1.0f);
    if (!m.alpha_texname.empty())
        out.alpha_texture =
            textures.get(m.alpha_texname, m.alpha_texopt, TexUse::alpha, "map_d of " + m.name);
    return out;
}

/// Rejects NaN/Inf in v, vn and vt (1-based element numbers as in the file).
void validate_attributes(const std::string& file, const tinyobj::attrib_t& attrib) {
    const std::pair<const std::vector<tinyobj::real_t>*, const char*> lists[] = {
        {&attrib.vertices, "v"}, {&attrib.normals, "vn"}, {&attrib.texcoords, "vt"}};
    for (const auto& [values, name] : lists) {
        const size_t stride = std::string(name) == "vt" ? 2 : 3;
        for (size_t i = 0; i < values->size(); ++i)
            if (!std::isfinite((*values)[i]))
                throw input_error(file, std::string(name) + " #" + std::to_string(i / stride + 1),
                                  "coordinate is not a finite number");
    }
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
    validate_attributes(file, attrib);
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
        model.meshes.push_back(std::move(mesh));
    }
}

/// tinyobjloader's warnings, one line each; a missing .mtl is reported by MtlFileReader, and
/// without materials (the BVH tools) unknown usemtl names are expected.
void log_obj_warnings(const std::string& file, const std::string& warn, bool materials) {
    std::istringstream warnings(warn);
    for (std::string line; std::getline(warnings, line);) {
        if (line.empty() || line.find("Failed to load material file") != std::string::npos) continue;
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
    reject_non_finite_words(file.string(), text);
    std::istringstream stream(text);
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

    LoadedModel model;
    ObjTextures textures(model, mtl_reader.texture_dir());
    for (const tinyobj::material_t& m : materials) model.materials.push_back(convert_material(m, textures));
    build_obj_meshes(file.string(), attrib, shapes, options.fan_split, model);
    if (model.meshes.empty()) throw input_error(file.string(), "", "no faces (is this an OBJ file?)");
    if (model.materials.empty()) model.materials.push_back(default_material());

    for (TriangleMesh& mesh : model.meshes) {
        transform_mesh(mesh, world_from_model);
        if (!options.keep_degenerate) model.dropped_degenerate += remove_degenerate(mesh);
    }
    std::erase_if(model.meshes, [](const TriangleMesh& m) { return m.indices.empty(); });
    if (model.dropped_degenerate > 0)
        log_info(file.string() + ": dropped " + std::to_string(model.dropped_degenerate) +
                 " zero-area triangles");
    return model;
}

}  // namespace sahara
