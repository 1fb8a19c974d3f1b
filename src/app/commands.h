#pragma once
/// The subcommands of `sahara`; each returns the process exit code.
#include <functional>
#include <string>
#include <vector>

#include "app/render_args.h"
#include "scene/scene_desc.h"

namespace sahara {

/// `sahara render`: arguments after the command name.
int run_render_command(const std::vector<std::string>& args);

/// Renders the scene `load_scene` returns with parsed render arguments (used by
/// `render` and `view`): output checks, signals, preview, resume, stats.
int run_render(const RenderArgs& args, const std::function<SceneDesc()>& load_scene);

/// `sahara view MODEL`: renders a downloaded model with no scene file.
int run_view_command(const std::vector<std::string>& args);

}  // namespace sahara
