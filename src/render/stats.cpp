#include "render/stats.h"

#include <algorithm>

namespace sahara {

void StatsReport::add(const std::string& group, const std::string& name, const std::string& text,
                      nlohmann::json value) {
    lines_.push_back({group, name, text, std::move(value)});
}

void StatsReport::add_count(const std::string& group, const std::string& name, uint64_t n) {
    add(group, name, std::to_string(n), n);
}

void StatsReport::add_bytes(const std::string& group, const std::string& name, uint64_t bytes) {
    add(group, name, format_bytes(bytes), bytes);
}

void StatsReport::add_seconds(const std::string& group, const std::string& name, double seconds) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f s", seconds);
    add(group, name, buf, seconds);
}

void StatsReport::add_ratio(const std::string& group, const std::string& name, double value,
                            const std::string& unit) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f %s", value, unit.c_str());
    add(group, name, buf, value);
}

void StatsReport::print(std::FILE* out) const {
    std::vector<std::string> groups;
    for (const Line& l : lines_)
        if (std::find(groups.begin(), groups.end(), l.group) == groups.end()) groups.push_back(l.group);
    std::fprintf(out, "Statistics:\n");
    for (const std::string& g : groups) {
        std::fprintf(out, "  %s\n", g.c_str());
        for (const Line& l : lines_)
            if (l.group == g) std::fprintf(out, "    %-36s %16s\n", l.name.c_str(), l.text.c_str());
    }
}

nlohmann::json StatsReport::to_json() const {
    nlohmann::json j = nlohmann::json::object();
    for (const Line& l : lines_) j[l.group][l.name] = l.value;
    return j;
}

uint64_t texture_bytes(const TextureDesc& t) {
    return t.image ? uint64_t(t.image->rgba.size()) * sizeof(float) : 0;
}

SceneMemory estimate_scene_memory(const Scene& scene) {
    SceneMemory m;
    m.spheres = scene.spheres.size() * sizeof(Sphere);
    const TriangleSoup& s = scene.triangles;
    m.triangles = s.positions.size() * sizeof(Vec3) + s.normals.size() * sizeof(Vec3) +
                  s.uvs.size() * sizeof(Vec2) + s.indices.size() * sizeof(uint32_t) +
                  s.material.size() * sizeof(uint32_t);
    m.other_geometry = scene.planes.size() * sizeof(Plane) + scene.boxes.size() * sizeof(Box);
    // Shared images (one texture used twice) count once.
    std::vector<const Image*> seen;
    for (const TextureDesc& t : scene.textures)
        if (t.image && std::find(seen.begin(), seen.end(), t.image.get()) == seen.end()) {
            seen.push_back(t.image.get());
            m.textures += texture_bytes(t);
        }
    if (scene.background.image) m.textures += uint64_t(scene.background.image->rgba.size()) * sizeof(float);
    const uint64_t bounded = scene.spheres.size() + scene.triangles.size() + scene.boxes.size();
    m.bvh_estimate = bounded * (2 * 32 + 4);
    // Instanced meshes count once, however many instances place them; they share the
    // scene's textures. Their trees are built, so their size is known, not estimated.
    for (const Scene* p : scene.prototypes()) {
        const SceneMemory pm = estimate_scene_memory(*p);
        m.spheres += pm.spheres;
        m.triangles += pm.triangles;
        m.other_geometry += pm.other_geometry;
    }
    m.bvh_estimate += scene.instance_level_bytes();
    return m;
}

std::string format_bytes(uint64_t bytes) {
    char buf[32];
    if (bytes < 1024)
        std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
    else if (bytes < 1024ull * 1024)
        std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
    else if (bytes < 1024ull * 1024 * 1024)
        std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / 1048576.0);
    else
        std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / 1073741824.0);
    return buf;
}

}  // namespace sahara
