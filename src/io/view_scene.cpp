#include "io/view_scene.h"

#include <cmath>

#include "base/error.h"
#include "base/log.h"
#include "math/bounds.h"
#include "io/scene_parser.h"

namespace sahara {

namespace {

Bounds3 model_bounds(const LoadedModel& model) {
    Bounds3 b;
    for (const TriangleMesh& m : model.meshes)
        for (const Vec3& p : m.positions) b.extend(p);
    return b;
}

Vec3 axis_vector(UpAxis a) { return a == UpAxis::y ? Vec3(0, 1, 0) : Vec3(0, 0, 1); }

/// Camera looking at the box from the front-right and above, far enough that
/// the bounding sphere fits the vertical field of view.
CameraDesc frame_box(const Bounds3& box, UpAxis up_axis, float vfov, float aspect) {
    const Vec3 up = axis_vector(up_axis);
    // Horizontal axes: for y up, x right and +z towards the viewer (glTF's front);
    // for z up, x right and -y towards the viewer.
    const Vec3 right(1, 0, 0), toward = up_axis == UpAxis::y ? Vec3(0, 0, 1) : Vec3(0, -1, 0);
    const Vec3 from_dir = normalize(right * 0.75f + toward * 1.0f + up * 0.55f);
    const float radius = 0.5f * length(box.extent());
    const float half = 0.5f * vfov * 3.14159265f / 180.0f;
    const float fit = std::min(std::tan(half), std::tan(half) * aspect);
    const float distance = radius / std::sin(std::atan(fit)) * 1.05f;
    CameraDesc cam;
    cam.look_at = box.center();
    cam.position = box.center() + from_dir * distance;
    cam.up = up;
    cam.vfov = vfov;
    return cam;
}

}  // namespace

UpAxis guess_up_axis(const LoadedModel& model, std::string& reason) {
    const Vec3 e = model_bounds(model).extent();
    // Models are usually Y-up; a model much taller along z than along y, with
    // y its thinnest axis, is almost surely Z-up (a standing figure or building).
    if (e.z > 1.5f * e.y && e.y <= e.x) {
        reason = "the model is elongated along z";
        return UpAxis::z;
    }
    reason = "most OBJ files are y-up";
    return UpAxis::y;
}

namespace {

/// The up axis: the user's, a glTF's (+y by the spec), or guessed for an OBJ.
UpAxis choose_up_axis(const LoadedModel& model, bool is_gltf, const ViewOptions& options) {
    if (options.up) return *options.up;
    if (is_gltf) return UpAxis::y;
    std::string reason;
    const UpAxis up = guess_up_axis(model, reason);
    log_info(std::string("up axis guessed as ") + (up == UpAxis::y ? "y" : "z") + " (" + reason +
             "); use --up y|z to change it");
    return up;
}

/// A checkered ground plane touching the lowest point of the model along `up`.
void add_ground(SceneDesc& scene, const Bounds3& box, UpAxis up) {
    const float radius = 0.5f * length(box.extent());
    MaterialDesc ground;
    ground.name = "view-ground";
    ground.albedo.kind = ColorSource::Kind::checker;
    ground.albedo.even = {0.75f, 0.75f, 0.75f};
    ground.albedo.odd = {0.55f, 0.55f, 0.55f};
    ground.albedo.checker_scale = std::max(radius * 0.25f, 1e-6f);
    scene.materials.push_back(ground);
    const float lowest = up == UpAxis::y ? box.lo.y : box.lo.z;
    PlaneDesc plane;
    plane.point = box.center();
    (up == UpAxis::y ? plane.point.y : plane.point.z) = lowest;
    plane.normal = axis_vector(up);
    plane.material = uint32_t(scene.materials.size() - 1);
    scene.planes.push_back(plane);
}

/// A warm sun from above, slightly to the side and front.
void add_sun(SceneDesc& scene, UpAxis up) {
    LightDesc sun;
    sun.type = LightDesc::Type::directional;
    sun.direction = -normalize(axis_vector(up) * 1.0f + Vec3(0.4f, 0, 0) +
                               (up == UpAxis::y ? Vec3(0, 0, 0.3f) : Vec3(0, -0.3f, 0)));
    sun.irradiance = {2.0f, 1.9f, 1.7f};
    scene.lights.push_back(sun);
}

}  // namespace

SceneDesc make_view_scene(LoadedModel model, bool is_gltf, const ViewOptions& options,
                          const std::string& source) {
    if (model.meshes.empty()) throw input_error(source, "", "the model has no triangles to show");
    SceneDesc scene;
    scene.source = source;
    scene.materials.push_back(default_material());
    scene.render.width = 800;
    scene.render.height = 600;
    scene.render.spp = 64;

    const UpAxis up = choose_up_axis(model, is_gltf, options);
    const Bounds3 box = model_bounds(model);
    std::vector<CameraDesc> cameras = model.cameras;
    merge_loaded_model(scene, std::move(model), std::nullopt);

    const float aspect = float(scene.render.width) / float(scene.render.height);
    if (options.gltf_camera) {
        if (*options.gltf_camera < 0 || size_t(*options.gltf_camera) >= cameras.size())
            throw input_error(source, "cameras[" + std::to_string(*options.gltf_camera) + "]",
                              "no such camera (the model has " + std::to_string(cameras.size()) + ")");
        scene.camera = cameras[size_t(*options.gltf_camera)];
    } else {
        scene.camera = frame_box(box, up, 35.0f, aspect);
    }
    scene.background.type = BackgroundDesc::Type::gradient;
    scene.background.up = axis_vector(up);
    if (options.ground) add_ground(scene, box, up);
    if (options.sun) add_sun(scene, up);
    return scene;
}

}  // namespace sahara
