#include "io/view_scene.h"

#include <cmath>

#include "base/error.h"
#include "base/log.h"
#include "math/bounds.h"
#include "io/image_io.h"
#include "io/mesh_utils.h"
#include "io/scene_parser.h"
#include "io/studio_environment.h"

namespace sahara {

namespace {

/// World bounds: the plain meshes' points, and each instance's prototype box
/// (in its own space) with its corners carried to the world.
Bounds3 model_bounds(const LoadedModel& model) {
    Bounds3 b;
    std::vector<bool> in_prototype(model.meshes.size(), false);
    std::vector<Bounds3> prototype_box(model.prototypes.size());
    for (size_t p = 0; p < model.prototypes.size(); ++p)
        for (uint32_t m : model.prototypes[p].meshes) {
            in_prototype[m] = true;
            prototype_box[p].extend(mesh_bounds(model.meshes[m]));
        }
    for (size_t m = 0; m < model.meshes.size(); ++m)
        if (!in_prototype[m])
            for (const Vec3& p : model.meshes[m].positions) b.extend(p);
    for (const InstanceDesc& in : model.instances) {
        const Bounds3& box = prototype_box[in.prototype];
        for (int corner = 0; corner < 8; ++corner)
            b.extend(in.world_from_object.apply_point({corner & 1 ? box.hi.x : box.lo.x,
                                                       corner & 2 ? box.hi.y : box.lo.y,
                                                       corner & 4 ? box.hi.z : box.lo.z}));
    }
    return b;
}

/// The model's front, towards the viewer: +z for y up (glTF's front), -y for z
/// up (the front view of Z-up tools); the negative axes turn both around.
Vec3 toward_viewer(UpAxis up) {
    switch (up) {
        case UpAxis::y:
            return {0, 0, 1};
        case UpAxis::neg_y:
            return {0, 0, -1};
        case UpAxis::z:
            return {0, -1, 0};
        case UpAxis::neg_z:
            return {0, 1, 0};
        case UpAxis::x:
        case UpAxis::neg_x:
            return {0, 0, 1};
    }
    return {0, 0, 1};
}

/// Camera looking at the box from the front-right and above, far enough that
/// the bounding sphere fits the vertical field of view.
CameraDesc frame_box(const Bounds3& box, UpAxis up_axis, float vfov, float aspect) {
    const Vec3 up = up_vector(up_axis), toward = toward_viewer(up_axis);
    const Vec3 right = cross(up, toward);
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

/// The up axis: the user's, a glTF's (+y by the spec), or the OBJ rule's; said on stderr.
UpAxis choose_up_axis(const LoadedModel& model, bool is_gltf, const ViewOptions& options,
                      const std::string& source) {
    if (options.up) return *options.up;
    const UpAxisChoice c = is_gltf ? UpAxisChoice{UpAxis::y, "glTF is +y up by its specification"}
                                   : guess_obj_up_axis(model, obj_header_comments(source));
    log_info(std::string("up axis ") + up_axis_name(c.axis) + ": " + c.reason +
             " (--up x|y|z|-x|-y|-z overrides it)");
    return c.axis;
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
    const Vec3 n = up_vector(up);
    PlaneDesc plane;
    plane.point = box.center() - n * (0.5f * std::abs(dot(box.extent(), n)));
    plane.normal = n;
    plane.material = uint32_t(scene.materials.size() - 1);
    scene.planes.push_back(plane);
}

/// A warm sun from above, slightly to the side and front: crisp contact shadows
/// beside the environment's soft light.
void add_sun(SceneDesc& scene, UpAxis up) {
    const Vec3 u = up_vector(up), toward = toward_viewer(up);
    LightDesc sun;
    sun.type = LightDesc::Type::directional;
    sun.direction = -normalize(u * 1.0f + cross(u, toward) * 0.4f + toward * 0.3f);
    sun.irradiance = {2.0f, 1.9f, 1.7f};
    scene.lights.push_back(sun);
}

/// The user's environment image, or the built-in studio.
BackgroundDesc view_background(const ViewOptions& options, UpAxis up) {
    const Vec3 u = up_vector(up);
    if (!options.env_file)
        return envmap_background(make_studio_environment(u, toward_viewer(up)), u, options.env_strength,
                                 "(built-in studio)");
    return envmap_background(read_image(*options.env_file, false), u, options.env_strength,
                             *options.env_file);
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

    const UpAxis up = choose_up_axis(model, is_gltf, options, source);
    scene.background = view_background(options, up);
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
    if (options.ground) add_ground(scene, box, up);
    if (options.sun) add_sun(scene, up);
    return scene;
}

}  // namespace sahara
