#pragma once
/// `sahara info [SCENE_OR_MODEL] [--variant NAME] [--json]`: what a scene or model holds
/// (objects, triangles, materials, textures, lights, bounds), its estimated
/// memory and how long it took to load and build.
#include <optional>
#include <string>
#include <vector>

#include "render/stats.h"

namespace sahara {

/// The report `sahara info` prints for a scene file, a model (in glTF material
/// variant `variant`, if given), or (nullopt) the built-in default scene.
/// Throws InputError.
StatsReport scene_info(const std::optional<std::string>& input,
                       const std::optional<std::string>& variant = std::nullopt);

/// `sahara info`: arguments after the command name; returns the exit code.
int run_info_command(const std::vector<std::string>& args);

}  // namespace sahara
