#include "app/cmd_info.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "app/cli_args.h"
#include "base/error.h"
#include "io/files.h"
#include "io/model_loader.h"
#include "render/features.h"
#include "render/stats.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

namespace sahara {

namespace fs = std::filesystem;

namespace {

const char* const kInfoUsage =
    "usage: sahara info [SCENE.json | MODEL.obj|.gltf|.glb] [--json]\n"
    "\n"
    "Describes a scene or model (the built-in default scene if none is given):\n"
    "objects, triangles, materials, textures, lights, bounds, estimated memory,\n"
    "load and build times.\n"
    "\n"
    "  --json       machine-readable output on stdout\n"
    "  -h, --help   this text\n";

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A scene file, or a model wrapped into a scene description.
SceneDesc load_input(const std::optional<std::string>& input) {
    if (!input) return default_scene();
    const FileKind kind = file_kind(*input);
    if (kind == FileKind::scene) return parse_scene_file(*input);
    if (is_model_kind(kind)) {
        LoadedModel m = load_model(*input);
        SceneDesc d;
        d.source = *input;
        d.meshes = std::move(m.meshes);
        d.materials = std::move(m.materials);
        d.textures = std::move(m.textures);
        d.lights = std::move(m.lights);
        return d;
    }
    throw input_error(*input, "", "unknown file type (expected .json, .obj, .gltf or .glb)");
}

const char* material_type_name(MaterialType t) {
    switch (t) {
        case MaterialType::lambertian:
            return "lambertian";
        case MaterialType::metal:
            return "metal";
        case MaterialType::dielectric:
            return "dielectric";
        case MaterialType::emissive:
            return "emissive";
        case MaterialType::pbr:
            return "pbr";
    }
    return "?";
}

std::string vec_text(const Vec3& v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "[%g, %g, %g]", double(v.x), double(v.y), double(v.z));
    return buf;
}

void describe_contents(StatsReport& s, const SceneDesc& d, const Scene& scene) {
    s.add("Scene", "Source", d.source, d.source);
    s.add_count("Objects", "Spheres", d.spheres.size());
    s.add_count("Objects", "Planes", d.planes.size());
    s.add_count("Objects", "Boxes", d.boxes.size());
    s.add_count("Objects", "Meshes", d.meshes.size());
    s.add_count("Objects", "Triangles", scene.triangles.size());
    s.add_count("Objects", "Vertices", scene.triangles.positions.size());
    s.add_count("Materials", "Total", d.materials.size());
    for (MaterialType t :
         {MaterialType::lambertian, MaterialType::metal, MaterialType::dielectric, MaterialType::emissive})
        s.add_count("Materials", material_type_name(t),
                    uint64_t(std::count_if(d.materials.begin(), d.materials.end(),
                                           [t](const MaterialDesc& m) { return m.type == t; })));
    s.add_count("Textures", "Total", d.textures.size());
    for (size_t i = 0; i < d.textures.size(); ++i) {
        const TextureDesc& t = d.textures[i];
        const int w = t.image ? t.image->width : 0, h = t.image ? t.image->height : 0;
        const std::string text =
            std::to_string(w) + "x" + std::to_string(h) + ", " + format_bytes(texture_bytes(t));
        std::string label("[");  // built piecewise: gcc 12 warns falsely (-Wrestrict) on a + chain here
        label.append(std::to_string(i)).append("] ").append(fs::path(t.path).filename().string());
        s.add("Textures", label, text,
              {{"path", t.path}, {"width", w}, {"height", h}, {"bytes", texture_bytes(t)}});
    }
    s.add_count("Lights", "Point",
                uint64_t(std::count_if(d.lights.begin(), d.lights.end(),
                                       [](const LightDesc& l) { return l.type == LightDesc::Type::point; })));
    s.add_count("Lights", "Directional",
                uint64_t(std::count_if(d.lights.begin(), d.lights.end(), [](const LightDesc& l) {
                    return l.type == LightDesc::Type::directional;
                })));
    s.add_count("Lights", "Emissive materials",
                uint64_t(std::count_if(d.materials.begin(), d.materials.end(), [](const MaterialDesc& m) {
                    return m.type == MaterialType::emissive;
                })));
    const Bounds3 b = scene.bounds();
    if (scene.primitive_count() > scene.planes.size()) {
        s.add("Bounds", "Min", vec_text(b.lo), {b.lo.x, b.lo.y, b.lo.z});
        s.add("Bounds", "Max", vec_text(b.hi), {b.hi.x, b.hi.y, b.hi.z});
    }
}

void describe_memory(StatsReport& s, const Scene& scene) {
    const SceneMemory m = estimate_scene_memory(scene);
    s.add_bytes("Memory", "Geometry", m.spheres + m.triangles + m.other_geometry);
    s.add_bytes("Memory", "BVH (estimate)", m.bvh_estimate);
    s.add_bytes("Memory", "Textures", m.textures);
    s.add_bytes("Memory", "Total", m.total());
}

}  // namespace

StatsReport scene_info(const std::optional<std::string>& input) {
    auto t = Clock::now();
    const SceneDesc desc = load_input(input);
    const double load = seconds_since(t);
    t = Clock::now();
    const Scene scene = build_scene(desc);
    const double build = seconds_since(t);
    StatsReport s;
    describe_contents(s, desc, scene);
    describe_memory(s, scene);
    const std::string features = describe_features(scene);
    s.add("Features", "Enabled", features, features);
    s.add_seconds("Time", "Load", load);
    s.add_seconds("Time", "Build", build);
    return s;
}

int run_info_command(const std::vector<std::string>& args) {
    std::optional<std::string> input;
    bool json = false, help = false;
    try {
        CLI::App app;
        configure_app(app, help);
        app.add_flag("--json", json);
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
        const StatsReport s = scene_info(input);
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
