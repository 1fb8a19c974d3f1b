#include "pipeline/mesh_input.h"

#include "base/error.h"
#include "base/log.h"
#include "io/files.h"
#include "io/generated_mesh.h"
#include "io/scene_parser.h"

namespace sahara {

SceneDesc read_scene_argument(const std::optional<std::string>& file) {
    if (!file) return default_scene();
    if (is_model_kind(file_kind(*file)))
        throw input_error(*file, "",
                          "a model, not a scene file (`sahara view " + *file + "` renders a model)");
    return parse_scene_file(*file);
}

ToolInput read_tool_input(const std::filesystem::path& file) {
    ToolInput in;
    if (file_kind(file) != FileKind::scene) {
        in.triangles = read_mesh_triangles(file);
        in.scene = scene_from_mesh(in.triangles);
        return in;
    }
    if (!std::filesystem::is_regular_file(file)) throw input_error(file.string(), "", "no such file");
    in.scene = build_scene(parse_scene_file(file));
    if (in.scene.instances())
        log_info(
            file.string() +
            ": the rays are traced through the scene's own tree only; its instance level is listed apart");
    in.from_scene_file = true;
    in.triangles.name = file.string();
    in.triangles.positions = in.scene.triangles.positions;
    in.triangles.indices = in.scene.triangles.indices;
    return in;
}

ToolInput generated_tool_input(size_t triangles) {
    ToolInput in;
    in.triangles = make_displaced_sphere(sphere_grid_for(triangles));
    in.scene = scene_from_mesh(in.triangles);
    return in;
}

std::string primitive_kinds_text(const Scene& scene, bool with_triangles) {
    const std::pair<size_t, const char*> kinds[] = {{with_triangles ? scene.triangles.size() : 0, "triangle"},
                                                    {scene.spheres.size(), "sphere"},
                                                    {scene.boxes.size(), "box"},
                                                    {scene.quadrics.size(), "quadric"}};
    std::string text;
    for (const auto& [count, name] : kinds) {
        if (count == 0) continue;
        if (!text.empty()) text += ", ";
        text += std::to_string(count) + " " + name;
        if (count != 1) text += std::string(name) == "box" ? "es" : "s";
    }
    return text.empty() ? "none" : text;
}

}  // namespace sahara
