#include "render/features.h"

#include "render/integrator.h"

namespace sahara {

std::string describe_features(const Scene& scene) {
    const SceneFeatures& f = scene.features;
    size_t points = 0, directionals = 0, spheres = 0, triangles = 0, boxes = 0;
    for (const Emitter& e : scene.emitters) {
        switch (e.kind) {
            case Emitter::Kind::point:
                ++points;
                break;
            case Emitter::Kind::directional:
                ++directionals;
                break;
            case Emitter::Kind::sphere:
                ++spheres;
                break;
            case Emitter::Kind::triangle:
                ++triangles;
                break;
            case Emitter::Kind::box:
                ++boxes;
                break;
            case Emitter::Kind::envmap:
                break;
        }
    }
    std::string s = "kernel ";
    s += path_kernel_name(scene);
    if (f.forced_all) s += " (all features forced on)";
    s += "; lights: " + std::to_string(points) + " point, " + std::to_string(directionals) + " directional";
    s += "; area lights: " + std::to_string(spheres) + " sphere, " + std::to_string(triangles) +
         " triangle, " + std::to_string(boxes) + " box";
    if (f.has_envmap) s += "; envmap importance sampling";
    if (f.has_emitters && !f.has_area_lights) s += "; emitters found by BSDF sampling only";
    s += "; materials: lambertian";
    if (f.has_metal) s += f.has_rough_metal ? ", metal (GGX)" : ", metal (mirror)";
    if (f.has_dielectric) s += ", dielectric";
    if (f.has_textures) s += "; textures";
    if (const size_t cutouts = scene.cutout_triangle_count())
        s += "; cut-outs (" + std::to_string(cutouts) + " alpha-tested triangles)";
    if (f.has_motion) s += "; motion blur";
    if (f.has_lens) s += "; depth of field";
    return s;
}

}  // namespace sahara
