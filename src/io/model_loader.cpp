#include "io/model_loader.h"

#include <algorithm>
#include <cctype>

#include "base/error.h"

namespace sahara {

LoadedModel load_model(const std::filesystem::path& file, const Mat4& world_from_model) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj(file, world_from_model);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(file, world_from_model);
    throw input_error(file.string(), "", "unknown model format '" + ext + "' (expected .obj, .gltf or .glb)");
}

}  // namespace sahara
