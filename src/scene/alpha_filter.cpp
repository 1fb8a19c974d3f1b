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

bool is_cutout_material(const MaterialDesc& m) {
    return m.alpha < 1.0f || m.alpha_texture >= 0 || m.vertex_alpha;
}

std::vector<uint8_t> one_sided_triangles(const Scene& scene) {
    std::vector<uint8_t> one_sided(scene.materials.size(), 0);
    bool any = false;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        one_sided[i] = scene.materials[i].double_sided ? 0 : 1;
        any |= !scene.materials[i].double_sided;
    }
    if (!any) return {};
    const TriangleSoup& soup = scene.triangles;
    std::vector<uint8_t> out(soup.size(), 0);
    bool used = false;
    for (size_t t = 0; t < soup.size(); ++t) {
        const uint32_t m = soup.material[t];
        out[t] = m < one_sided.size() ? one_sided[m] : 0;
        used |= out[t] != 0;
    }
    return used ? out : std::vector<uint8_t>{};
}

AlphaFilter::AlphaFilter(const Scene& scene) {
    std::vector<bool> cut(scene.materials.size(), false);
    std::vector<uint32_t> cutout_of(scene.materials.size(), kOpaque);
    bool any = false;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        cut[i] = is_cutout_material(scene.materials[i]);
        any |= cut[i];
    }
    if (!any) return;
    warn_untested_kinds(scene, cut);
    const TriangleSoup& soup = scene.triangles;
    for (uint32_t t = 0; t < soup.size(); ++t) {
        const uint32_t m = soup.material[t];
        if (m >= cut.size() || !cut[m]) continue;
        if (cutout_of[m] == kOpaque) {
            const MaterialDesc& md = scene.materials[m];
            Cutout c;
            c.alpha = md.alpha;
            c.cutoff = md.alpha_cutoff ? *md.alpha_cutoff : -1.0f;
            c.vertex_alpha = md.vertex_alpha && !soup.color_alphas.empty();
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
        for (int k = 0; k < 3; ++k) {
            const uint32_t vertex = soup.indices[3 * size_t(t) + size_t(k)];
            tri.uv[k] = soup.uvs.empty() ? bary[k] : soup.uvs[vertex];
            tri.vertex_alpha[k] = soup.color_alphas.empty() ? 1.0f : soup.color_alphas[vertex];
        }
        tri.cutout = cutout_of[m];
        entry_[t] = uint32_t(triangles_.size());
        triangles_.push_back(tri);
    }
}

float AlphaFilter::alpha(uint32_t entry, float u, float v) const {
    const Triangle& tri = triangles_[entry];
    const Cutout& c = cutouts_[tri.cutout];
    const float w = 1.0f - u - v;
    float a = c.alpha;
    if (c.vertex_alpha) a *= tri.vertex_alpha[0] * w + tri.vertex_alpha[1] * u + tri.vertex_alpha[2] * v;
    if (c.texture < 0) return a;
    const Vec2 uv{tri.uv[0].x * w + tri.uv[1].x * u + tri.uv[2].x * v,
                  tri.uv[0].y * w + tri.uv[1].y * u + tri.uv[2].y * v};
    float texture_alpha = 1.0f;
    sample_texture_rgb(textures_[size_t(c.texture)], uv, &texture_alpha);
    return a * texture_alpha;
}

bool AlphaFilter::passes(uint32_t entry, const Ray& ray, uint32_t prim_id, float u, float v) const {
    const Cutout& c = cutouts_[triangles_[entry].cutout];
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
