#include "render/features.h"

#include <vector>

#include "render/integrator.h"

namespace sahara {

namespace {

/// The material types the scene's primitives use, in the scene format's order (a
/// loaded model's unused default material is no "lambertian"); metal and
/// dielectric as the kernel sees them (any material of the type).
std::string material_types(const Scene& scene) {
    std::vector<bool> used(scene.materials.size(), false);
    const auto use = [&used](uint32_t m) {
        if (m < used.size()) used[m] = true;
    };
    for (uint32_t m : scene.triangles.material) use(m);
    for (const Sphere& p : scene.spheres) use(p.material);
    for (const Box& p : scene.boxes) use(p.material);
    for (const Plane& p : scene.planes) use(p.material);
    for (const Quadric& p : scene.quadrics) use(p.material);
    bool lambertian = false, emissive = false;
    for (size_t i = 0; i < used.size(); ++i) {
        lambertian |= used[i] && scene.materials[i].type == MaterialType::lambertian;
        emissive |= used[i] && scene.materials[i].type == MaterialType::emissive;
    }
    const SceneFeatures& f = scene.features;
    std::string types;
    const auto add = [&types](const char* name) { types += types.empty() ? name : std::string(", ") + name; };
    if (lambertian) add("lambertian");
    if (f.has_metal) add(f.has_rough_metal ? "metal (GGX)" : "metal (mirror)");
    if (f.has_dielectric) add("dielectric");
    if (emissive) add("emissive");
    if (f.has_pbr) add("pbr (metallic-roughness)");
    if (f.has_unlit) add("unlit");
    return types.empty() ? std::string("none") : types;
}

/// Triangles whose material is one-sided: the accelerator culls their back faces.
size_t one_sided_triangle_count(const Scene& scene) {
    size_t n = 0;
    for (uint32_t m : scene.triangles.material)
        n += m < scene.materials.size() && !scene.materials[m].double_sided ? 1 : 0;
    return n;
}

}  // namespace

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
            case Emitter::Kind::instanced_triangle:  // counted as drawn: once per instance
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
    s += "; materials: " + material_types(scene);
    if (f.has_textures) s += "; textures";
    if (const size_t cutouts = scene.cutout_triangle_count())
        s += "; cut-outs (" + std::to_string(cutouts) + " alpha-tested triangles)";
    if (const size_t one_sided = one_sided_triangle_count(scene))
        s += "; one-sided (" + std::to_string(one_sided) + " triangles with back faces culled)";
    if (f.has_motion) s += "; motion blur";
    if (f.has_lens) s += "; depth of field";
    return s;
}

}  // namespace sahara
