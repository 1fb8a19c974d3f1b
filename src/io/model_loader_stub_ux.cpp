// TEMPORARY (branch ux only): lets `sahara info` link before the model loaders
// land; the lead deletes this file at merge.
#include "base/error.h"
#include "io/model_loader.h"

namespace sahara {

LoadedModel load_model(const std::filesystem::path& file, const Mat4&) {
    throw input_error(file.string(), "", "model loading not available yet");
}

}  // namespace sahara
