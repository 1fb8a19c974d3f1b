/// Scene::prepare_lighting: the emitter list for light sampling, its power
/// distribution, the envmap distribution and the scene's feature set. Plain
/// data only; the sampling code that reads it is in render/lights.cpp.
#include <cmath>
#include <numbers>

#include "scene/instances.h"
#include "scene/scene.h"
#include "scene/texture.h"

namespace sahara {

namespace {

constexpr float kPiF = std::numbers::pi_v<float>;

/// A rough mean of a colour source, enough to pick lights by power.
float mean_color(const ColorSource& c) {
    switch (c.kind) {
        case ColorSource::Kind::constant:
            return average(c.color);
        case ColorSource::Kind::checker:
            return 0.5f * (average(c.even) + average(c.odd));
        case ColorSource::Kind::texture:
            return average(c.color);  // the texture's mean is not known here
    }
    return average(c.color);
}

/// Emissive materials and glowing pbr ones (glTF emissiveFactor) are area lights.
bool is_sampled_emitter(const MaterialDesc& m) {
    return (m.type == MaterialType::emissive || m.type == MaterialType::pbr) && mean_color(m.radiance) > 0;
}

float triangle_area(const TriangleSoup& soup, size_t i) {
    const Vec3& p0 = soup.positions[soup.indices[3 * i]];
    return 0.5f * length(cross(soup.positions[soup.indices[3 * i + 1]] - p0,
                               soup.positions[soup.indices[3 * i + 2]] - p0));
}

float bounding_radius(const Scene& s) {
    Bounds3 b;
    for (const Sphere& sp : s.spheres) b.extend(sp.bounds(s.camera.shutter_open, s.camera.shutter_close));
    for (const Vec3& p : s.triangles.positions) b.extend(p);
    for (const Box& bx : s.boxes) b.extend(bx.box);
    if (s.instances()) b.extend(s.instances()->bounds());
    if (b.empty()) return 1.0f;
    const float r = 0.5f * length(b.extent());
    return r > 0 && std::isfinite(r) ? r : 1.0f;
}

/// Envmap pixel weights: luminance times sin(theta) of the row centre, since a
/// lat-long pixel covers a solid angle proportional to sin(theta).
std::vector<float> envmap_weights(const Image& img, double* mean_radiance) {
    std::vector<float> w(size_t(img.width) * size_t(img.height));
    double total = 0, solid = 0;
    for (int y = 0; y < img.height; ++y) {
        const float sin_theta = std::sin(kPiF * (float(y) + 0.5f) / float(img.height));
        for (int x = 0; x < img.width; ++x) {
            const float* p = &img.rgba[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
            const float lum = std::max(0.0f, luminance(Rgb(p[0], p[1], p[2])));
            const float v = std::isfinite(lum) ? lum * sin_theta : 0.0f;
            w[size_t(y) * size_t(img.width) + size_t(x)] = v;
            total += double(v);
            solid += double(sin_theta);
        }
    }
    *mean_radiance = solid > 0 ? total / solid : 0.0;
    return w;
}

/// Point and directional lights: the power a point light emits in all
/// directions; the part of a directional light's flux that crosses the scene.
void collect_lights(const Scene& s, float disk, std::vector<Emitter>& emitters, std::vector<float>& power) {
    for (uint32_t i = 0; i < s.lights.size(); ++i) {
        const LightDesc& l = s.lights[i];
        const bool point = l.type == LightDesc::Type::point;
        const float p = point ? 4.0f * kPiF * average(l.intensity) : disk * average(l.irradiance);
        if (!(p > 0)) continue;
        emitters.push_back({point ? Emitter::Kind::point : Emitter::Kind::directional, i});
        power.push_back(p);
    }
}

/// Adds area emitter i if its material emits; a Lambertian emitter of area A
/// and radiance L emits pi * A * L (`radiance`: L's estimate, mean_color by default).
void add_area_emitter(std::vector<uint32_t>& map, size_t count, Emitter::Kind kind, uint32_t i, float area,
                      const MaterialDesc& m, std::vector<Emitter>& emitters, std::vector<float>& power,
                      float radiance = -1.0f) {
    if (!is_sampled_emitter(m) || !(area > 0)) return;
    if (radiance < 0.0f) radiance = mean_color(m.radiance);
    if (!(radiance > 0.0f)) return;
    if (map.empty()) map.assign(count, kNoEmitter);
    map[i] = uint32_t(emitters.size());
    emitters.push_back({kind, i});
    power.push_back(kPiF * area * radiance);
}

/// The emission of a triangle with a textured pbr emission, averaged over seven points
/// (corners, edge midpoints, centroid) in the UVs the texture reads: a triangle over a
/// dark part of the texture draws few light samples, and one that is black at all seven
/// is left to BSDF sampling (unbiased still: MIS gives hits on non-emitters weight 1).
float textured_pbr_radiance(const Scene& s, uint32_t i, const MaterialDesc& m) {
    const TriangleSoup& soup = s.triangles;
    const Vec3 p0 = soup.positions[soup.indices[3 * size_t(i)]];
    const Vec3 p1 = soup.positions[soup.indices[3 * size_t(i) + 1]];
    const Vec3 p2 = soup.positions[soup.indices[3 * size_t(i) + 2]];
    const Vec3 n = cross(p1 - p0, p2 - p0);
    const Vec2 bary[7] = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0}, {0, 0.5f}, {0.5f, 0.5f}, {1 / 3.0f, 1 / 3.0f}};
    const TextureDesc& tex = s.textures[size_t(m.radiance.texture)];
    float sum = 0;
    for (const Vec2& b : bary) {
        const Vec3 p = p0 * (1.0f - b.x - b.y) + p1 * b.x + p2 * b.y;
        const SurfaceInteraction si = s.interact(Ray{p + n, -n, 0.0f, 2.0f, 0.0f},
                                                 Hit{1.0f, make_prim_id(PrimKind::triangle, i), b.x, b.y});
        sum += average(eval_color(m.radiance, s.textures, si.p, tex.texcoord == 1 ? si.uv1 : si.uv));
    }
    return sum / 7.0f;
}

/// The light-sampling radiance estimate of triangle i (mean_color but for textured pbr emission).
float triangle_radiance(const Scene& s, uint32_t i, const MaterialDesc& m) {
    const bool textured = m.type == MaterialType::pbr && m.radiance.kind == ColorSource::Kind::texture &&
                          m.radiance.texture >= 0 && size_t(m.radiance.texture) < s.textures.size() &&
                          s.textures[size_t(m.radiance.texture)].image;
    return textured ? textured_pbr_radiance(s, i, m) : mean_color(m.radiance);
}

void collect_features(const Scene& s, SceneFeatures& f) {
    for (const MaterialDesc& m : s.materials) {
        f.has_emitters |= (m.type == MaterialType::emissive && mean_color(m.radiance) > 0) ||
                          (m.type == MaterialType::lambertian && max_component(m.emission) > 0) ||
                          (m.type == MaterialType::pbr && mean_color(m.radiance) > 0);
        f.has_pbr |= m.type == MaterialType::pbr;
        f.has_unlit |= m.type == MaterialType::unlit;
        f.has_metal |= m.type == MaterialType::metal;
        f.has_rough_metal |= m.type == MaterialType::metal && m.roughness > 0;
        f.has_dielectric |= m.type == MaterialType::dielectric;
        f.has_textures |=
            m.albedo.kind != ColorSource::Kind::constant || m.radiance.kind != ColorSource::Kind::constant;
    }
    f.lambertian_only = !f.has_metal && !f.has_dielectric && !f.has_pbr && !f.has_unlit;
    const bool shutter = s.camera.shutter_close > s.camera.shutter_open;
    for (const Sphere& sp : s.spheres) f.has_motion |= shutter && sp.velocity != Vec3(0.0f);
    if (s.instances()) f.has_motion |= shutter && s.instances()->has_motion();
    f.has_lens = s.camera.aperture > 0;
}

void force_all(SceneFeatures& f) {
    f.has_lights = f.has_emitters = f.has_area_lights = f.has_envmap = true;
    f.has_delta_lights_only = false;
    f.has_motion = f.has_lens = f.has_textures = true;
    f.has_metal = f.has_rough_metal = f.has_dielectric = f.has_pbr = true;
    f.lambertian_only = false;  // has_unlit stays as found: it changes what is rendered, not only how fast
    f.forced_all = true;
}

}  // namespace

void Scene::collect_instanced_emitters(std::vector<float>& power) {
    instanced_emitters.clear();
    instance_emitter_base_.clear();
    prototype_emitter_slot_.clear();
    if (!instances_) return;
    // Per prototype: which triangles emit (their slot) and their radiance estimate.
    std::vector<std::vector<float>> radiance(instances_->prototype_count());
    prototype_emitter_slot_.resize(instances_->prototype_count());
    bool any = false;
    for (uint32_t in = 0; in < instances_->instance_count(); ++in) {
        const uint32_t p = instances_->prototype_index(in);
        const Scene& proto = instances_->prototype_of(in);
        std::vector<uint32_t>& slot = prototype_emitter_slot_[p];
        if (slot.empty() && proto.triangles.size() > 0) {
            slot.assign(proto.triangles.size(), kNoEmitter);
            for (uint32_t i = 0; i < proto.triangles.size(); ++i) {
                const MaterialDesc& m = proto.materials[proto.triangles.material[i]];
                const float r = is_sampled_emitter(m) ? triangle_radiance(proto, i, m) : 0.0f;
                if (!(r > 0)) continue;
                slot[i] = uint32_t(radiance[p].size());
                radiance[p].push_back(r);
            }
        }
        any |= !radiance[p].empty();
    }
    if (!any) return;
    instance_emitter_base_.assign(instances_->instance_count(), kNoEmitter);
    for (uint32_t in = 0; in < instances_->instance_count(); ++in) {
        const uint32_t p = instances_->prototype_index(in);
        if (radiance[p].empty()) continue;
        instance_emitter_base_[in] = uint32_t(emitters.size());
        const TriangleSoup& soup = instances_->prototype_of(in).triangles;
        const Mat4& m = instances_->world_from_object(in);
        for (uint32_t i = 0; i < soup.size(); ++i) {
            const uint32_t k = prototype_emitter_slot_[p][i];
            if (k == kNoEmitter) continue;
            InstancedEmitter e;
            e.p0 = m.apply_point(soup.positions[soup.indices[3 * size_t(i)]]);
            e.p1 = m.apply_point(soup.positions[soup.indices[3 * size_t(i) + 1]]);
            e.p2 = m.apply_point(soup.positions[soup.indices[3 * size_t(i) + 2]]);
            e.velocity = instances_->velocity(in);
            e.instance = in;
            e.triangle = i;
            e.material = soup.material[i];
            // Every slot gets its entry (ids are base + slot); a degenerate one gets no power.
            const float area = 0.5f * length(cross(e.p1 - e.p0, e.p2 - e.p0));
            emitters.push_back({Emitter::Kind::instanced_triangle, uint32_t(instanced_emitters.size())});
            power.push_back(area > 0 ? kPiF * area * radiance[p][k] : 0.0f);
            instanced_emitters.push_back(e);
        }
    }
}

uint32_t Scene::instanced_emitter(uint32_t instance, uint32_t triangle) const {
    if (instance_emitter_base_.empty()) return kNoEmitter;
    const uint32_t base = instance_emitter_base_[instance];
    if (base == kNoEmitter) return kNoEmitter;
    const uint32_t k = prototype_emitter_slot_[instances_->prototype_index(instance)][triangle];
    return k == kNoEmitter ? kNoEmitter : base + k;
}

void Scene::prepare_lighting(bool force_all_features) {
    emitters.clear();
    sphere_emitter.clear();
    triangle_emitter.clear();
    box_emitter.clear();
    envmap_emitter = kNoEmitter;
    scene_radius = bounding_radius(*this);
    const float disk = kPiF * scene_radius * scene_radius;  // cross-section of the scene
    std::vector<float> power;

    collect_lights(*this, disk, emitters, power);
    const size_t delta_count = emitters.size();
    for (uint32_t i = 0; i < spheres.size(); ++i)
        add_area_emitter(sphere_emitter, spheres.size(), Emitter::Kind::sphere, i,
                         4.0f * kPiF * spheres[i].radius * spheres[i].radius, materials[spheres[i].material],
                         emitters, power);
    for (uint32_t i = 0; i < triangles.size(); ++i) {
        const MaterialDesc& m = materials[triangles.material[i]];
        if (!is_sampled_emitter(m)) continue;
        add_area_emitter(triangle_emitter, triangles.size(), Emitter::Kind::triangle, i,
                         triangle_area(triangles, i), m, emitters, power, triangle_radiance(*this, i, m));
    }
    for (uint32_t i = 0; i < boxes.size(); ++i)
        add_area_emitter(box_emitter, boxes.size(), Emitter::Kind::box, i, boxes[i].box.surface_area(),
                         materials[boxes[i].material], emitters, power);
    collect_instanced_emitters(power);
    const size_t area_count = emitters.size() - delta_count;

    envmap_distribution = Distribution2D();
    const Image* img = background.type == BackgroundDesc::Type::envmap ? background.image.get() : nullptr;
    if (img && img->width > 0 && img->height > 0 && background.strength > 0) {
        double mean = 0;
        const std::vector<float> w = envmap_weights(*img, &mean);
        if (mean > 0) {
            envmap_distribution = Distribution2D(w, img->width, img->height);
            envmap_emitter = uint32_t(emitters.size());
            emitters.push_back({Emitter::Kind::envmap, 0});
            power.push_back(4.0f * kPiF * disk * float(mean) * background.strength);  // 4 pi sr over the disk
        }
    }
    emitter_distribution = Distribution1D(std::move(power));

    features = SceneFeatures();
    features.has_lights = delta_count > 0;
    features.has_area_lights = area_count > 0;
    features.has_envmap = envmap_emitter != kNoEmitter;
    features.has_delta_lights_only = features.has_lights && !features.has_area_lights && !features.has_envmap;
    collect_features(*this, features);
    if (force_all_features) force_all(features);
}

}  // namespace sahara
