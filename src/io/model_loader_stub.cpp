// TEMPORARY (parser branch only): lets this branch link before the model
// loader branch is merged. The lead deletes this file on merge.
#include "base/error.h"
#include "io/model_loader.h"

namespace sahara {

LoadedModel load_model(const std::filesystem::path& file, const Mat4&) {
    throw input_error(file.string(), "", "mesh loading not available in this build");
}
LoadedModel load_obj(const std::filesystem::path& file, const Mat4&) {
    throw input_error(file.string(), "", "mesh loading not available in this build");
}
LoadedModel load_gltf(const std::filesystem::path& file, const Mat4&) {
    throw input_error(file.string(), "", "mesh loading not available in this build");
}

}  // namespace sahara
