#include "app/cmd_info.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "app/cli_args.h"
#include "base/error.h"
#include "base/text.h"
#include "io/files.h"
#include "io/model_loader.h"
#include "pipeline/scene_info.h"
#include "render/stats.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

namespace sahara {

namespace fs = std::filesystem;

namespace {

const char* const kInfoUsage =
    "usage: sahara info [SCENE.json | MODEL.obj|.gltf|.glb] [--variant NAME] [--json]\n"
    "\n"
    "Describes a scene or model (the built-in default scene if none is given):\n"
    "objects, triangles, materials, textures, lights, bounds, estimated memory,\n"
    "load and build times. Each material is listed by what it uses (type,\n"
    "textures, vertex colours, emission, transmission, alpha, one-sided);\n"
    "'Ignored inputs' names what the file gives that is not rendered (e.g. a\n"
    "glTF occlusion map, unsupported extensions, volume attenuation).\n"
    "\n"
    "  --variant NAME  describe the glTF model in its material variant NAME\n"
    "  --json       machine-readable output on stdout\n"
    "  -h, --help   this text\n";

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A scene file, or a model (in material variant `variant`, if given) wrapped
/// into a scene description (its material variants, if any, in `variants`).
SceneDesc load_input(const std::optional<std::string>& input, const std::optional<std::string>& variant,
                     std::vector<std::string>& variants) {
    if (!input) return default_scene();
    const FileKind kind = file_kind(*input);
    if (variant && !is_model_kind(kind))
        throw input_error(*input, "",
                          "--variant applies to a glTF model; a scene file names its variants "
                          "with the mesh object's \"variant\" key");
    if (kind == FileKind::scene) return parse_scene_file(*input);
    if (is_model_kind(kind)) {
        LoadedModel m = load_model(*input, Mat4::identity(), SharedMeshes::copy, variant);
        variants = std::move(m.variants);
        SceneDesc d;
        d.source = *input;
        merge_loaded_model(d, std::move(m), std::nullopt);
        return d;
    }
    throw input_error(*input, "", "unknown file type (expected .json, .obj, .gltf or .glb)");
}

}  // namespace

StatsReport scene_info(const std::optional<std::string>& input, const std::optional<std::string>& variant) {
    auto t = Clock::now();
    std::vector<std::string> variants;
    const SceneDesc desc = load_input(input, variant, variants);
    const double load = seconds_since(t);
    t = Clock::now();
    const Scene scene = build_scene(desc);
    const double build = seconds_since(t);
    StatsReport s = describe_scene(desc, scene);
    if (!variants.empty()) {
        s.add("Material variants", "KHR_materials_variants", join(variants), variants);
        s.add("Material variants", "Rendered", variant ? *variant : "the default materials",
              variant ? nlohmann::json(*variant) : nlohmann::json());
    }
    s.add_seconds("Time", "Load", load);
    s.add_seconds("Time", "Build", build);
    return s;
}

int run_info_command(const std::vector<std::string>& args) {
    std::optional<std::string> input;
    std::optional<std::string> variant;
    bool json = false, help = false;
    try {
        CLI::App app;
        configure_app(app, help);
        app.add_flag("--json", json);
        app.add_option_function<std::string>("--variant", [&variant](const std::string& v) { variant = v; });
        const std::vector<std::string> inputs = parse_command_line(app, args);
        if (inputs.size() > 1)
            throw UsageError("more than one input given ('" + inputs[0] + "' and '" + inputs[1] + "')");
        if (!inputs.empty()) input = inputs[0];
    } catch (const UsageError& e) {
        return usage_error("info", e.what());
    }
    if (help) {
        std::fputs(kInfoUsage, stdout);
        return 0;
    }
    try {
        const StatsReport s = scene_info(input, variant);
        if (json)
            std::printf("%s\n", s.to_json().dump(2).c_str());
        else
            s.print(stdout);
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara: error: %s\n", e.what());
        return 2;
    }
}

}  // namespace sahara
