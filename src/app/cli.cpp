#include "app/cli.h"

#include <cstdio>
#include <string>
#include <vector>

#include "app/cmd_converge.h"
#include "app/cmd_info.h"
#include "app/cmd_version.h"
#include "app/commands.h"
#include "app/tool_args.h"
#include "base/error.h"

namespace sahara {

namespace {

const char* const kUsage =
    "sahara — a CPU path tracer for meshes and spheres\n"
    "\n"
    "usage: sahara COMMAND [options]\n"
    "\n"
    "commands:\n"
    "  render [SCENE.json]   render a scene (or the built-in default scene) to an image\n"
    "  view MODEL            render a downloaded model (.obj, .gltf, .glb) with no scene file\n"
    "  converge [SCENE]      measure error against run time at doubling spp; CSV + log-log plot\n"
    "  info [SCENE|MODEL]    what a scene holds: objects, triangles, materials, memory\n"
    "  bvh MESH              build the BVH and print its statistics\n"
    "  bench MESH            trace fixed ray sets and compare with Embree\n"
    "  trace MESH            trace rays from a file and write the hits\n"
    "\n"
    "  sahara COMMAND --help   options of a command\n"
    "  sahara --version        the version and the optional parts built in\n";

}  // namespace

int run_cli(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty()) {
        std::fputs(kUsage, stderr);
        return 2;
    }
    const std::string& cmd = args[0];
    if (cmd == "-h" || cmd == "--help" || cmd == "help") {
        std::fputs(kUsage, stdout);
        return 0;
    }
    if (cmd == "--version" || cmd == "-V" || cmd == "version") return run_version_command();
    const std::vector<std::string> rest(args.begin() + 1, args.end());
    if (cmd == "render") return run_render_command(rest);
    if (cmd == "info") return run_info_command(rest);
    if (cmd == "view") return run_view_command(rest);
    if (cmd == "converge") return run_converge_command(rest);
    if (cmd == "bvh") return run_bvh_command(argc - 1, argv + 1);
    if (cmd == "bench") return run_bench_command(argc - 1, argv + 1);
    if (cmd == "trace") return run_trace_command(argc - 1, argv + 1);
    return usage_error("", std::string(cmd[0] == '-' ? "unknown option '" : "unknown command '") + cmd + "'");
}

}  // namespace sahara
