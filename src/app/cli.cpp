#include "app/cli.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "app/cmd_converge.h"
#include "app/cmd_info.h"
#include "app/cmd_version.h"
#include "app/commands.h"
#include "app/cli_args.h"
#include "base/error.h"
#include "io/image_codec.h"

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
    "  sahara --version        the version and the optional parts built in\n"
    "\n"
    "  --image-codec FILE      (before the command) load the image codec plugin from FILE\n"
    "                          instead of looking beside the executable and in ../lib/sahara\n";

/// The command's entry point, given the words after the command name.
int dispatch(const std::string& cmd, const std::vector<std::string>& rest) {
    if (cmd == "render") return run_render_command(rest);
    if (cmd == "info") return run_info_command(rest);
    if (cmd == "view") return run_view_command(rest);
    if (cmd == "converge") return run_converge_command(rest);
    // The tool commands take argc/argv with argv[0] the command name.
    std::vector<std::string> words{cmd};
    words.insert(words.end(), rest.begin(), rest.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    const int argc = int(words.size());
    if (cmd == "bvh") return run_bvh_command(argc, argv.data());
    if (cmd == "bench") return run_bench_command(argc, argv.data());
    return run_trace_command(argc, argv.data());
}

}  // namespace

int run_cli(int argc, char** argv) {
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty()) {
        std::fputs(kUsage, stderr);
        return 2;
    }
    CLI::App app;
    bool help = false, version = false;
    std::string codec_file;
    configure_app(app, help);
    app.add_flag("-V,--version", version);
    app.add_option("--image-codec", codec_file);
    for (const char* name :
         {"render", "view", "info", "converge", "bvh", "bench", "trace", "version", "help"}) {
        CLI::App* sub = app.add_subcommand(name);
        sub->set_help_flag();   // the command parses its own words, --help included
        sub->prefix_command();  // every word after the command name is the command's
    }
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 consumes from the back
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        return usage_error("", e.what());
    }
    const std::vector<CLI::App*> chosen = app.get_subcommands();
    const std::string cmd = chosen.empty() ? "" : chosen[0]->get_name();
    if (help || cmd == "help") {
        std::fputs(kUsage, stdout);
        return 0;
    }
    set_image_codec_file(codec_file);
    if (version || cmd == "version") return run_version_command();
    if (cmd.empty() || !app.remaining().empty()) {
        const std::string first = app.remaining().empty() ? args[0] : app.remaining()[0];
        return usage_error("", (first[0] == '-' ? "unknown option '" : "unknown command '") + first + "'");
    }
    try {
        return dispatch(cmd, chosen[0]->remaining());
    } catch (const std::bad_alloc&) {
        // A film of 32768 x 32768 pixels alone needs 36 GiB: a size the format
        // allows can still be more than the machine has.
        std::fputs("sahara: error: out of memory (a smaller image or scene needs less)\n", stderr);
        return 2;
    }
}

}  // namespace sahara
