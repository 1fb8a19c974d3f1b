#pragma once
/// `sahara view`: turns a downloaded model into a complete scene with no scene
/// file — a camera framing it from a three-quarter view, a ground plane under
/// it, a studio environment (or the user's) and a sun.
#include <optional>
#include <string>

#include "io/model_loader.h"
#include "io/up_axis.h"
#include "desc/scene_desc.h"

namespace sahara {

struct ViewOptions {
    std::optional<UpAxis> up;        ///< none: +y for glTF, the rule of up_axis.h for OBJ
    std::optional<int> gltf_camera;  ///< use the model's camera with this index
    bool ground = true;
    bool sun = true;
    std::optional<std::string> env_file;  ///< the user's lat-long environment; none: the built-in studio
    float env_strength = 1.0f;
};

/// Builds the viewing scene. `is_gltf` selects the glTF default (+y up); for an
/// OBJ the up axis is chosen from the model and the header of `source`, and the
/// choice and its reason go to stderr. Throws InputError for an unreadable --env file.
SceneDesc make_view_scene(LoadedModel model, bool is_gltf, const ViewOptions& options,
                          const std::string& source);

}  // namespace sahara
