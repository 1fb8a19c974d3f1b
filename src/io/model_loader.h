#pragma once
/// Loads a downloaded model (.obj with its .mtl, .gltf, .glb) into plain scene
/// data. Loaders never build acceleration structures.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "math/transform.h"
#include "desc/scene_desc.h"

namespace sahara {

/// Everything a model file holds that sahara can show. Material and texture
/// indices in `meshes` refer into this struct's own vectors.
struct LoadedModel {
    std::vector<TriangleMesh> meshes;
    std::vector<MaterialDesc> materials;
    std::vector<TextureDesc> textures;
    std::vector<LightDesc> lights;    ///< KHR_lights_punctual
    std::vector<CameraDesc> cameras;  ///< glTF cameras, world space
    /// glTF meshes that several nodes draw, or that an EXT_mesh_gpu_instancing node
    /// draws: each one prototype (mesh indices into `meshes`, in the mesh's own
    /// space) placed by one instance per node or per entry.
    std::vector<PrototypeDesc> prototypes;
    std::vector<InstanceDesc> instances;
    size_t dropped_degenerate = 0;  ///< zero-area triangles removed
    /// KHR_materials_variants names, for `sahara info`, and the one rendered (none: the default materials).
    std::vector<std::string> variants;
    std::optional<std::string> variant;
};

/// What a loader does with a glTF mesh that several nodes draw: copy it per node
/// (every consumer of plain meshes), or load it once as a prototype placed by
/// LoadedModel::instances (scene files, which the renderer instances). Nodes with
/// EXT_mesh_gpu_instancing give instances either way; consumers that need every
/// triangle in world space call bake_instances.
enum class SharedMeshes : uint8_t { copy, instance };

/// Replaces the model's prototypes and instances by world-space copies of the
/// prototypes' meshes, one per instance, in instance order after the other meshes.
void bake_instances(LoadedModel& model);

/// Picks the loader by extension. Throws InputError naming the file and element.
/// `world_from_model` is applied to positions/normals (and glTF node transforms before it).
/// `variant` names the glTF KHR_materials_variants variant to render (an InputError
/// if the file has no such variant; OBJ files have none).
LoadedModel load_model(const std::filesystem::path& file, const Mat4& world_from_model = Mat4::identity(),
                       SharedMeshes shared = SharedMeshes::copy,
                       const std::optional<std::string>& variant = std::nullopt);
LoadedModel load_obj(const std::filesystem::path& file, const Mat4& world_from_model = Mat4::identity());

/// How load_obj reads a file for the BVH tools (io/mesh_triangles.h) rather than for rendering.
struct ObjReadOptions {
    bool materials = true;         ///< false: no mtllib, no textures; every face gets the default material
    bool fan_split = false;        ///< true: polygon v0..vk gives (v0,v1,v2), (v0,v2,v3)... (no ear clipping)
    bool keep_degenerate = false;  ///< true: zero-area triangles stay, so triangle i is the file's i-th
};
LoadedModel load_obj(const std::filesystem::path& file, const Mat4& world_from_model,
                     const ObjReadOptions& options);
LoadedModel load_gltf(const std::filesystem::path& file, const Mat4& world_from_model = Mat4::identity(),
                      SharedMeshes shared = SharedMeshes::copy,
                      const std::optional<std::string>& variant = std::nullopt);

}  // namespace sahara
