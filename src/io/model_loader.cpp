#include "io/model_loader.h"

#include "base/error.h"
#include "io/files.h"

namespace sahara {

LoadedModel load_model(const std::filesystem::path& file, const Mat4& world_from_model, SharedMeshes shared) {
    switch (file_kind(file)) {
        case FileKind::obj:
            return load_obj(file, world_from_model);
        case FileKind::gltf:
            return load_gltf(file, world_from_model, shared);
        default:
            throw input_error(
                file.string(), "",
                "unknown model format '" + file.extension().string() + "' (expected .obj, .gltf or .glb)");
    }
}

}  // namespace sahara
