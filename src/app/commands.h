#pragma once
/// The subcommands of `sahara`; each returns the process exit code.
#include <functional>
#include <string>
#include <vector>

#include "app/render_args.h"
#include "desc/scene_desc.h"

namespace sahara {

/// `sahara render`: arguments after the command name.
int run_render_command(const std::vector<std::string>& args);

/// Renders the scene `load_scene` returns with parsed render arguments (used by
/// `render` and `view`): output checks, signals, preview, resume, stats.
int run_render(const RenderArgs& args, const std::function<SceneDesc()>& load_scene);

/// `sahara view MODEL`: renders a downloaded model with no scene file.
int run_view_command(const std::vector<std::string>& args);

// BVH tools: argv[0] is the subcommand name; exit code 0 ok, 2 bad usage or
// bad input; each prints its usage on --help.

/// `sahara bvh FILE [--builder binned|sweep|reinsert|sbvh|auto] [--size WxH|N] [--json]`: tree statistics.
int run_bvh_command(int argc, char** argv);
/// `sahara bench MESH [--threads N] [--ray-set primary|diffuse|shadow|all] [--json]`: throughput vs Embree.
int run_bench_command(int argc, char** argv);
/// `sahara trace MESH --rays IN.rays --hits OUT.hits [--occlusion OUT.occl]`: trace a ray file.
int run_trace_command(int argc, char** argv);

}  // namespace sahara
