#include "io/model_loader.h"

#include "base/error.h"
#include "io/files.h"
#include "io/mesh_utils.h"

namespace sahara {

LoadedModel load_model(const std::filesystem::path& file, const Mat4& world_from_model, SharedMeshes shared,
                       const std::optional<std::string>& variant) {
    switch (file_kind(file)) {
        case FileKind::obj:
            if (variant)
                throw input_error(file.string(), "",
                                  "material variant '" + *variant +
                                      "' asked for, but only glTF files have material variants");
            return load_obj(file, world_from_model);
        case FileKind::gltf:
            return load_gltf(file, world_from_model, shared, variant);
        default:
            throw input_error(
                file.string(), "",
                "unknown model format '" + file.extension().string() + "' (expected .obj, .gltf or .glb)");
    }
}

void bake_instances(LoadedModel& model) {
    if (model.instances.empty() && model.prototypes.empty()) return;
    std::vector<bool> in_prototype(model.meshes.size(), false);
    for (const PrototypeDesc& p : model.prototypes)
        for (uint32_t m : p.meshes) in_prototype[m] = true;
    std::vector<TriangleMesh> meshes;
    for (size_t m = 0; m < model.meshes.size(); ++m)
        if (!in_prototype[m]) meshes.push_back(std::move(model.meshes[m]));
    for (const InstanceDesc& in : model.instances)
        for (uint32_t m : model.prototypes[in.prototype].meshes) {
            TriangleMesh copy = model.meshes[m];
            transform_mesh(copy, in.world_from_object);
            meshes.push_back(std::move(copy));
        }
    model.meshes = std::move(meshes);
    model.prototypes.clear();
    model.instances.clear();
}

}  // namespace sahara
