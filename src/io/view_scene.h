#pragma once
/// `sahara view`: turns a downloaded model into a complete scene with no scene
/// file — a camera framing it from a three-quarter view, a ground plane under
/// it, the sky gradient and a sun.
#include <optional>
#include <string>

#include "io/model_loader.h"
#include "desc/scene_desc.h"

namespace sahara {

enum class UpAxis : uint8_t { y, z };

struct ViewOptions {
    std::optional<UpAxis> up;        ///< none: y for glTF, guessed for OBJ
    std::optional<int> gltf_camera;  ///< use the model's camera with this index
    bool ground = true;
    bool sun = true;
};

/// The up axis sahara assumes for a model whose file does not say: the axis
/// along which the model is tallest relative to its footprint (y unless the
/// model is clearly elongated along z). `reason` receives a short explanation.
UpAxis guess_up_axis(const LoadedModel& model, std::string& reason);

/// Builds the viewing scene. `is_gltf` selects the glTF default (y up).
SceneDesc make_view_scene(LoadedModel model, bool is_gltf, const ViewOptions& options,
                          const std::string& source);

}  // namespace sahara
