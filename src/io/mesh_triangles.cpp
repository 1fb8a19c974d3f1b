#include "io/mesh_triangles.h"

#include "io/files.h"
#include "io/model_loader.h"

namespace sahara {

namespace {

/// Every mesh of `model` as one: positions appended, indices shifted, triangle order kept.
TriangleMesh merge_meshes(const LoadedModel& model, const std::string& name) {
    TriangleMesh all;
    all.name = name;
    for (const TriangleMesh& m : model.meshes) {
        const auto base = uint32_t(all.positions.size());
        all.positions.insert(all.positions.end(), m.positions.begin(), m.positions.end());
        for (uint32_t i : m.indices) all.indices.push_back(base + i);
    }
    return all;
}

}  // namespace

TriangleMesh read_obj_triangles(const std::filesystem::path& file) {
    // io's OBJ loader in its geometry-only mode: the tools' documented
    // triangle order (fan split, degenerate triangles kept) without materials.
    const ObjReadOptions tool_order{.materials = false, .fan_split = true, .keep_degenerate = true};
    return merge_meshes(load_obj(file, Mat4::identity(), tool_order), file.string());
}

TriangleMesh read_mesh_triangles(const std::filesystem::path& file) {
    if (file_kind(file) != FileKind::gltf) return read_obj_triangles(file);
    LoadedModel model = load_model(file);
    bake_instances(model);
    return merge_meshes(model, file.string());
}

}  // namespace sahara
