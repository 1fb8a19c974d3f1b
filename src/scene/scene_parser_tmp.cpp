#include "base/error.h"
#include "scene/scene_parser.h"

namespace sahara {

SceneDesc parse_scene_file(const std::filesystem::path& file) {
    throw input_error(file.string(), "", "scene files are not supported yet");
}

SceneDesc default_scene() {
    SceneDesc d;
    d.source = "<default>";
    d.materials.push_back(default_material());
    MaterialDesc red, green;
    red.name = "red"; red.albedo.color = {0.8f, 0.1f, 0.1f};
    green.name = "green"; green.albedo.color = {0.2f, 0.7f, 0.2f};
    d.materials.push_back(red);
    d.materials.push_back(green);
    d.spheres.push_back({{0, 10, 0}, 5, 1, {0, 0, 0}});
    d.spheres.push_back({{0, 10, -100}, 95, 2, {0, 0, 0}});
    d.camera.position = {0, 0, 0};
    d.camera.look_at = {0, 1, 0};
    d.camera.up = {0, 0, 1};
    d.camera.vfov = 90;
    return d;
}

}  // namespace sahara
