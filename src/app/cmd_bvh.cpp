/// `sahara bvh`: builds the BVH over a mesh or a scene file's bounded primitives
/// and prints its statistics, plus
/// the mean traversal work per ray for primary, diffuse-bounce and shadow (occlusion) rays.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <cstdio>
#include <optional>
#include <string>

#include "scene/accelerator.h"
#include "accel/bvh_stats.h"
#include "pipeline/bvh_report.h"
#include "app/commands.h"
#include "pipeline/mesh_input.h"
#include "app/cli_args.h"
#include "base/error.h"

namespace sahara {

namespace {

constexpr const char* kBvhUsage =
    "usage: sahara bvh FILE [--builder binned|sweep|reinsert|sbvh|auto] [--layout L] [--threads N]\n"
    "                       [--size WxH|N] [--json]\n"
    "  FILE        a mesh (.obj, .gltf, .glb; OBJ polygons are fan-split, degenerate triangles kept)\n"
    "              or a scene file (.json): the tree holds its triangles, spheres, boxes and quadrics;\n"
    "              planes are unbounded, stay outside the tree and are not traced here\n"
    "  --builder   binned (default: binned SAH, parallel), sweep (exact sweep SAH) or reinsert\n"
    "              (binned SAH, then insertion-based reinsertion of the most inefficient nodes);\n"
    "              a scene file's render.bvh_builder when not given\n"
    "  --layout L  traversal structure the counts below are taken on: wide8 (default) or pairs\n"
    "              (see `sahara bench --help`)\n"
    "  --threads N threads for the build (default: all cores)\n"
    "  --size WxH  primary rays W x H, N x N for one number (default 1024, i.e. 1M), as many\n"
    "              diffuse-bounce rays and as many shadow rays (occlusion, to a light above or a\n"
    "              scene's sun; the sets of `sahara bench`); a mesh is framed from (0.4, 0.3, 1), a\n"
    "              scene is seen through its own camera\n"
    "  --json      print one JSON object instead of text\n"
    "SAH costs: traversal 1, primitive intersection 1 (relative), normalised to the root's area.\n";

struct BvhArgs {
    std::string file;
    std::optional<BvhBuilder> builder;  ///< none: the scene's render.bvh_builder (for a mesh, the default)
    std::optional<BvhLayout> layout;
    std::optional<int> width, height;  ///< the primary-ray grid (default 1024 x 1024)
    int threads = 0;
    bool json = false;
    bool help = false;
};

nlohmann::ordered_json bvh_report(const BvhArgs& args) {
    const ToolInput input = read_tool_input(args.file);
    BvhReportOptions o;
    o.builder = args.builder;
    o.layout = args.layout;
    o.threads = args.threads;
    o.width = args.width.value_or(1024);
    o.height = args.height.value_or(1024);
    o.from_scene_file = input.from_scene_file;
    return bvh_report(input.scene, args.file, o);
}

void print_text(const nlohmann::ordered_json& j) {
    std::printf("%-17s %s\n", j["input"].get<std::string>().c_str(), j["mesh"].get<std::string>().c_str());
    std::printf("builder           %s\n", j["builder"].get<std::string>().c_str());
    std::printf("layout            %s", j["layout"].get<std::string>().c_str());
    if (j["layout"] != "pairs") std::printf(" (%zu wide nodes)", j["wide_nodes"].get<size_t>());
    std::printf("\n");
    std::printf("primitives        %zu (%s)\n", j["primitives"].get<size_t>(),
                j["primitive_kinds"].get<std::string>().c_str());
    if (const auto planes = j["planes_outside_tree"].get<size_t>())
        std::printf("planes            %zu, unbounded: not in the tree, not traced here\n", planes);
    std::printf("nodes             %zu (%zu leaves)\n", j["nodes"].get<size_t>(), j["leaves"].get<size_t>());
    std::printf("leaf depth        max %d, mean %.2f\n", j["max_depth"].get<int>(),
                j["mean_leaf_depth"].get<double>());
    std::printf("leaf sizes        ");
    const auto hist = j["leaf_size_histogram"].get<std::vector<size_t>>();
    for (size_t k = 1; k < hist.size(); ++k)
        if (hist[k]) std::printf("%zu:%zu ", k, hist[k]);
    std::printf("\nSAH cost          %.3f (traversal %g, intersection %g, root area = 1)\n",
                j["sah_cost"].get<double>(), j["traversal_cost"].get<double>(),
                j["intersection_cost"].get<double>());
    if (j.contains("wide")) {
        const auto& w = j["wide"];
        std::printf(
            "wide tree         %zu nodes, %.2f children per node, %zu leaves, blocks of %u %.1f%% full\n",
            w["nodes"].get<size_t>(), w["children_per_node"].get<double>(), w["leaves"].get<size_t>(),
            w["leaf_block_size"].get<unsigned>(), 100.0 * w["leaf_block_fill"].get<double>());
        std::printf(
            "wide SAH          nodes %.3f + leaves %.3f = %.3f (Embree's verbose report: area / root\n"
            "                  area summed over nodes, and over leaves times their blocks)\n",
            w["sah_nodes"].get<double>(), w["sah_leaves"].get<double>(),
            w["sah_nodes"].get<double>() + w["sah_leaves"].get<double>());
    }
    std::printf("build             %.1f ms (%.2f Mprims/s), CPU time %.1f ms (%.2f Mprims/s), %d threads\n",
                j["build_ms"].get<double>(), j["mprims_s"].get<double>(), j["build_cpu_ms"].get<double>(),
                j["mprims_cpu_s"].get<double>(), j["build_threads"].get<int>());
    std::printf(
        "memory            %zu bytes (%.1f per primitive; tree %zu, leaf-ordered primitives the rest)\n",
        j["bytes"].get<size_t>(), j["bytes_per_primitive"].get<double>(), j["tree_bytes"].get<size_t>());
    if (j.contains("instances")) {
        const auto& in = j["instances"];
        std::printf(
            "instances         %zu of %zu prototypes; top-level tree %zu nodes (%zu leaves, depth %d)\n",
            in["instances"].get<size_t>(), in["prototypes"].get<size_t>(),
            in["top_level_nodes"].get<size_t>(), in["top_level_leaves"].get<size_t>(),
            in["top_level_max_depth"].get<int>());
        std::printf(
            "                  %zu triangles stored, %zu drawn; %zu bytes (the counts above and below\n"
            "                  are the scene's own tree, without the instances)\n",
            in["triangles_stored"].get<size_t>(), in["triangles_drawn"].get<size_t>(),
            in["bytes"].get<size_t>());
    }
    for (const char* set : {"primary", "diffuse", "shadow"}) {
        const auto& r = j["rays"][set];
        std::printf("%-7s rays      %zu: %.1f nodes visited, %.2f primitives tested per ray\n", set,
                    r["count"].get<size_t>(), r["nodes_visited"].get<double>(),
                    r["prims_tested"].get<double>());
    }
}

BvhArgs parse_bvh_args(const std::vector<std::string>& words) {
    BvhArgs a;
    a.threads = omp_get_num_procs();
    CLI::App app;
    configure_app(app, a.help);
    app.add_option_function<std::string>(
        "--builder", [&a](const std::string& v) { a.builder = parse_builder_name("--builder", v); });
    app.add_option_function<std::string>(
        "--layout", [&a](const std::string& v) { a.layout = parse_layout_name("--layout", v); });
    add_threads_option(app, a.threads);
    add_size_option(app, a.width, a.height);
    app.add_flag("--json", a.json);
    const std::vector<std::string> files = parse_command_line(app, words);
    if (!a.help && files.size() != 1) throw UsageError("expected one mesh or scene file");
    if (!a.help) a.file = files[0];
    return a;
}

}  // namespace

int run_bvh_command(int argc, char** argv) {
    BvhArgs args;
    try {
        args = parse_bvh_args(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const UsageError& e) {
        return usage_error("bvh", e.what());
    }
    if (args.help) {
        std::fputs(kBvhUsage, stdout);
        return 0;
    }
    try {
        const nlohmann::ordered_json j = bvh_report(args);
        if (args.json)
            std::printf("%s\n", j.dump().c_str());
        else
            print_text(j);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara bvh: %s\n", e.what());
        return 2;
    }
    return 0;
}

}  // namespace sahara
