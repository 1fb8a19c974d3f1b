#include "pipeline/scene_info.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "pipeline/material_info.h"
#include "render/features.h"
#include "scene/instances.h"

namespace sahara {

namespace fs = std::filesystem;

namespace {

/// `digits` significant digits: 6 (printf's default) unless the values sit
/// far from the origin, where 6 would hide everything but the offset.
std::string vec_text(const Vec3d& v, int digits = 6) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "[%.*g, %.*g, %.*g]", digits, v.x, digits, v.y, digits, v.z);
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
    describe_materials(s, d);
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
                uint64_t(std::count_if(d.materials.begin(), d.materials.end(), emits_light)));
    if (const InstanceSet* in = scene.instances()) {
        s.add_count("Instances", "Prototypes", in->prototype_count());
        s.add_count("Instances", "Instances", in->instance_count());
        s.add_count("Instances", "Triangles stored", in->unique_triangle_count());
        s.add_count("Instances", "Triangles drawn", in->instanced_triangle_count());
        s.add_bytes("Instances", "Trees", in->bytes());
    }
    const Bounds3 b = scene.bounds();
    // World coordinates: the scene is stored relative to its local origin.
    const int digits = d.origin == Vec3d(0, 0, 0) ? 6 : 12;
    if (d.origin != Vec3d(0, 0, 0))
        s.add("Bounds", "Local origin", vec_text(d.origin, digits), {d.origin.x, d.origin.y, d.origin.z});
    if (scene.primitive_count() > scene.planes.size() || scene.instances()) {
        const Vec3d lo = Vec3d(b.lo) + d.origin, hi = Vec3d(b.hi) + d.origin;
        s.add("Bounds", "Min", vec_text(lo, digits), {lo.x, lo.y, lo.z});
        s.add("Bounds", "Max", vec_text(hi, digits), {hi.x, hi.y, hi.z});
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

StatsReport describe_scene(const SceneDesc& desc, const Scene& scene) {
    StatsReport s;
    describe_contents(s, desc, scene);
    describe_memory(s, scene);
    const std::string features = describe_features(scene);
    s.add("Features", "Enabled", features, features);
    return s;
}

}  // namespace sahara
