#include "scene/alpha_filter.h"

#include <bit>
#include <string>

#include "base/log.h"
#include "geometry/hit.h"
#include "scene/texture.h"
#include "scene/scene.h"

namespace sahara {

namespace {

/// The 64-bit finaliser of MurmurHash3 (Appleby): every input bit affects every output bit.
uint64_t mix64(uint64_t h) {
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return h;
}

/// Warns once about primitives other than triangles that use a cut-out material.
void warn_untested_kinds(const Scene& scene, const std::vector<bool>& cut) {
    size_t others = 0;
    auto count = [&](uint32_t material) { others += material < cut.size() && cut[material] ? 1 : 0; };
    for (const Sphere& s : scene.spheres) count(s.material);
    for (const Box& b : scene.boxes) count(b.material);
    for (const Plane& p : scene.planes) count(p.material);
    for (const Quadric& q : scene.quadrics) count(q.material);
    if (others)
        log_warning(std::to_string(others) +
                    " non-triangle primitive(s) use a cut-out material; alpha applies to triangles "
                    "only, they render opaque");
}

}  // namespace

float cutout_hash(const Ray& ray, uint32_t prim_id) {
    const float f[6] = {ray.origin.x, ray.origin.y, ray.origin.z, ray.dir.x, ray.dir.y, ray.dir.z};
    uint64_t h = mix64(0x9e3779b97f4a7c15ull ^ prim_id);
    for (float x : f) h = mix64(h ^ std::bit_cast<uint32_t>(x));
    // The top 24 bits: exactly representable, so the result is below 1.
    return float(h >> 40) * 0x1p-24f;
}

bool is_cutout_material(const MaterialDesc& m) { return m.alpha < 1.0f || m.alpha_texture >= 0; }

bool needs_alpha_filter(const MaterialDesc& m) {
    return is_cutout_material(m) || (m.type == MaterialType::pbr && !m.double_sided);
}

AlphaFilter::AlphaFilter(const Scene& scene) {
    std::vector<bool> cut(scene.materials.size(), false), holes(scene.materials.size(), false);
    std::vector<uint32_t> cutout_of(scene.materials.size(), kOpaque);
    bool any = false;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        cut[i] = needs_alpha_filter(scene.materials[i]);
        holes[i] = is_cutout_material(scene.materials[i]);
        any |= cut[i];
    }
    if (!any) return;
    warn_untested_kinds(scene, holes);
    const TriangleSoup& soup = scene.triangles;
    for (uint32_t t = 0; t < soup.size(); ++t) {
        const uint32_t m = soup.material[t];
        if (m >= cut.size() || !cut[m]) continue;
        if (cutout_of[m] == kOpaque) {
            const MaterialDesc& md = scene.materials[m];
            Cutout c;
            c.alpha = md.alpha;
            c.cutoff = md.alpha_cutoff ? *md.alpha_cutoff : -1.0f;
            c.single_sided = md.type == MaterialType::pbr && !md.double_sided;
            if (md.alpha_texture >= 0 && size_t(md.alpha_texture) < scene.textures.size() &&
                scene.textures[size_t(md.alpha_texture)].image) {
                c.texture = int(textures_.size());
                textures_.push_back(scene.textures[size_t(md.alpha_texture)]);
            }
            cutout_of[m] = uint32_t(cutouts_.size());
            cutouts_.push_back(c);
        }
        if (entry_.empty()) entry_.assign(soup.size(), kOpaque);
        Triangle tri{};
        // Without UVs, interact() uses the barycentrics as uv: the same here.
        const Vec2 bary[3] = {{0, 0}, {1, 0}, {0, 1}};
        for (int k = 0; k < 3; ++k)
            tri.uv[k] = soup.uvs.empty() ? bary[k] : soup.uvs[soup.indices[3 * size_t(t) + size_t(k)]];
        const Vec3& p0 = soup.positions[soup.indices[3 * size_t(t)]];
        tri.normal = cross(soup.positions[soup.indices[3 * size_t(t) + 1]] - p0,
                           soup.positions[soup.indices[3 * size_t(t) + 2]] - p0);
        tri.cutout = cutout_of[m];
        entry_[t] = uint32_t(triangles_.size());
        triangles_.push_back(tri);
    }
}

float AlphaFilter::alpha(uint32_t entry, float u, float v) const {
    const Triangle& tri = triangles_[entry];
    const Cutout& c = cutouts_[tri.cutout];
    if (c.texture < 0) return c.alpha;
    const float w = 1.0f - u - v;
    const Vec2 uv{tri.uv[0].x * w + tri.uv[1].x * u + tri.uv[2].x * v,
                  tri.uv[0].y * w + tri.uv[1].y * u + tri.uv[2].y * v};
    float a = 1.0f;
    sample_texture_rgb(textures_[size_t(c.texture)], uv, &a);
    return c.alpha * a;
}

bool AlphaFilter::passes(uint32_t entry, const Ray& ray, uint32_t prim_id, float u, float v) const {
    const Cutout& c = cutouts_[triangles_[entry].cutout];
    if (c.single_sided && dot(triangles_[entry].normal, ray.dir) >= 0) return false;  // its back face
    const float cutoff = c.cutoff;
    const float a = alpha(entry, u, v);
    if (cutoff >= 0.0f) return a >= cutoff;
    if (a >= 1.0f) return true;
    if (a <= 0.0f) return false;
    return cutout_hash(ray, prim_id) < a;
}

size_t AlphaFilter::bytes() const {
    return entry_.size() * sizeof(uint32_t) + triangles_.size() * sizeof(Triangle) +
           cutouts_.size() * sizeof(Cutout);
}

}  // namespace sahara
