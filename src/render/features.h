#pragma once
/// A human-readable account of the machinery a scene's render uses.
#include <string>

#include "scene/scene.h"

namespace sahara {

/// One line listing the enabled features (for `sahara info` and `render --stats`).
std::string describe_features(const Scene& scene);

}  // namespace sahara
