// TEMPORARY (parser branch only): lets this branch link before the model
// loader and image I/O branches are merged. The lead deletes this file on merge.
#include "base/error.h"
#include "io/image_io.h"
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
std::shared_ptr<const Image> read_image(const std::filesystem::path& file, bool) {
    throw input_error(file.string(), "", "image loading not available in this build");
}

}  // namespace sahara
