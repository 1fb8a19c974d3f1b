#include "render/lights.h"

#include <array>
#include <cmath>

#include "geometry/spawn.h"
#include "math/sampling.h"
#include "render/background.h"
#include "render/bsdf_pbr.h"
#include "scene/texture.h"

namespace sahara {

namespace {

/// Shadow rays stop this fraction short of the light so that they never hit the light itself.
constexpr float kShadowEpsilon = 1e-4f;

/// 1 - cos(theta_max) of the cone a sphere subtends; for tiny cones from the
/// Taylor series, where 1 - sqrt(1 - x) cancels catastrophically in float.
float cone_one_minus_cos(float sin2_max) {
    if (sin2_max < 0.00068523f) return 0.5f * sin2_max;  // sin^2(1.5 degrees)
    return 1.0f - std::sqrt(std::max(0.0f, 1.0f - sin2_max));
}

/// A point on the part of the sphere visible from p, uniform in solid angle
/// (the cone construction of pbrt-v4, "Sampling Spheres"). False if p is
/// inside the sphere: its emitting outside cannot be seen from there.
bool sample_sphere_cone(const Sphere& s, const Vec3& p, float time, Vec2 u, Vec3* p_light, Vec3* n_light,
                        float* pdf) {
    const Vec3 c = s.center_at(time);
    const float dc2 = length_squared(c - p), r2 = s.radius * s.radius;
    if (dc2 <= r2) return false;
    const float sin2_max = r2 / dc2, sin_max = std::sqrt(sin2_max);
    const float one_minus_cos_max = cone_one_minus_cos(sin2_max);
    float cos_theta = 1.0f - u.x * one_minus_cos_max;
    float sin2_theta = std::max(0.0f, 1.0f - cos_theta * cos_theta);
    if (sin2_max < 0.00068523f) {  // same small-angle care as above
        sin2_theta = sin2_max * u.x;
        cos_theta = std::sqrt(1.0f - sin2_theta);
    }
    // Angle at the centre between the axis towards p and the sampled point.
    const float cos_alpha =
        sin2_theta / sin_max + cos_theta * std::sqrt(std::max(0.0f, 1.0f - sin2_theta / sin2_max));
    const float sin_alpha = std::sqrt(std::max(0.0f, 1.0f - cos_alpha * cos_alpha));
    const float phi = 2.0f * kPi * u.y;
    const Vec3 n = Frame(normalize(p - c))
                       .to_world(Vec3(sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha));
    *n_light = n;
    *p_light = c + n * s.radius;
    *pdf = 1.0f / (2.0f * kPi * one_minus_cos_max);
    return true;
}

/// A uniform point on the triangle (p0, p1, p2) (barycentrics by the square-root warp).
Vec3 sample_triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, Vec2 u, Vec3* n, float* area,
                     Vec2* bary) {
    const float su = std::sqrt(u.x);
    const float b1 = u.y * su, b2 = 1.0f - su;
    const Vec3 c = cross(p1 - p0, p2 - p0);
    const float len = length(c);
    *n = c / len;
    *area = 0.5f * len;
    *bary = {b1, b2};
    return p0 * (1.0f - b1 - b2) + p1 * b1 + p2 * b2;
}

/// Face areas of a box per axis (each axis has two such faces).
Vec3 box_face_areas(const Bounds3& b) {
    const Vec3 e = b.extent();
    return {e.y * e.z, e.z * e.x, e.x * e.y};
}

/// A uniform point on the surface of a box: a face by area, then a point on it.
Vec3 sample_box(const Bounds3& b, Vec2 u, Vec3* n) {
    const Vec3 a = box_face_areas(b);
    const float total = a.x + a.y + a.z;
    float pick = u.x * total;
    int axis = 0;
    while (axis < 2 && pick >= a[axis]) pick -= a[axis++];
    // The remainder of u.x within the chosen axis picks the side and the first coordinate.
    const float t = a[axis] > 0 ? std::clamp(pick / a[axis], 0.0f, 0x1.fffffep-1f) : 0.0f;
    const bool high = t >= 0.5f;
    const float s1 = high ? 2.0f * t - 1.0f : 2.0f * t;
    const int i1 = (axis + 1) % 3, i2 = (axis + 2) % 3;
    Vec3 p;
    p[axis] = high ? b.hi[axis] : b.lo[axis];
    p[i1] = b.lo[i1] + s1 * (b.hi[i1] - b.lo[i1]);
    p[i2] = b.lo[i2] + u.y * (b.hi[i2] - b.lo[i2]);
    *n = Vec3(0.0f);
    (*n)[axis] = high ? 1.0f : -1.0f;
    return p;
}

uint32_t material_of(const Scene& scene, const Emitter& e) {
    switch (e.kind) {
        case Emitter::Kind::sphere:
            return scene.spheres[e.index].material;
        case Emitter::Kind::triangle:
            return scene.triangles.material[e.index];
        case Emitter::Kind::box:
            return scene.boxes[e.index].material;
        case Emitter::Kind::instanced_triangle:
            return scene.instanced_emitters[e.index].material;
        default:
            return 0;
    }
}

/// The hit that would have found the sampled point of emitter e (barycentrics bary).
Hit hit_of(const Scene& scene, const Emitter& e, Vec2 bary) {
    if (e.kind == Emitter::Kind::instanced_triangle) {
        const InstancedEmitter& t = scene.instanced_emitters[e.index];
        return Hit{1.0f, make_prim_id(PrimKind::triangle, t.triangle), bary.x, bary.y, t.instance};
    }
    const PrimKind kind = e.kind == Emitter::Kind::sphere     ? PrimKind::sphere
                          : e.kind == Emitter::Kind::triangle ? PrimKind::triangle
                                                              : PrimKind::box;
    return Hit{1.0f, make_prim_id(kind, e.index), bary.x, bary.y};
}

/// A point on an area emitter with its outward normal and its density per unit solid angle at p.
bool sample_area_point(const Scene& scene, const Emitter& e, const Vec3& p, float time, Vec2 u, Vec3* pl,
                       Vec3* nl, float* pdf_solid, Vec2* bary) {
    float area = 0;
    switch (e.kind) {
        case Emitter::Kind::sphere:
            return sample_sphere_cone(scene.spheres[e.index], p, time, u, pl, nl, pdf_solid);
        case Emitter::Kind::triangle: {
            const TriangleSoup& soup = scene.triangles;
            const uint32_t* v = &soup.indices[3 * size_t(e.index)];
            *pl = sample_triangle(soup.positions[v[0]], soup.positions[v[1]], soup.positions[v[2]], u, nl,
                                  &area, bary);
            break;
        }
        case Emitter::Kind::instanced_triangle: {
            const InstancedEmitter& t = scene.instanced_emitters[e.index];
            const Vec3 shift = t.velocity * time;
            *pl = sample_triangle(t.p0 + shift, t.p1 + shift, t.p2 + shift, u, nl, &area, bary);
            break;
        }
        case Emitter::Kind::box: {
            const Bounds3& b = scene.boxes[e.index].box;
            *pl = sample_box(b, u, nl);
            area = b.surface_area();
            break;
        }
        default:
            return false;
    }
    const Vec3 d = *pl - p;
    const float dist2 = length_squared(d);
    const float cos_l = -dot(*nl, d) / std::sqrt(dist2);
    if (!(cos_l > 0) || !(area > 0)) return false;  // back side or degenerate
    *pdf_solid = dist2 / (cos_l * area);
    return true;
}

bool sample_area_light(const Scene& scene, const Emitter& e, const Vec3& p, float time, Vec2 u,
                       LightSample& ls) {
    Vec3 pl, nl;
    Vec2 bary{0, 0};
    float pdf_solid = 0;
    if (!sample_area_point(scene, e, p, time, u, &pl, &nl, &pdf_solid, &bary)) return false;
    const Vec3 d = pl - p;
    ls.distance = length(d);
    if (!(ls.distance > 0)) return false;
    ls.wi = d / ls.distance;
    if (dot(nl, ls.wi) >= 0) return false;  // only the front side emits
    const MaterialDesc& m = scene.materials[material_of(scene, e)];
    const bool coated = m.type == MaterialType::pbr && m.layers.clearcoat > 0;
    if (m.radiance.kind == ColorSource::Kind::constant && !coated) {
        ls.li = m.radiance.color;
    } else {
        // Textured or coated emission: let the scene compute the point exactly as for a hit.
        const Ray r{p, d, 0.0f, 2.0f, time};
        const SurfaceInteraction si = scene.interact(r, hit_of(scene, e, bary));
        ls.li = m.type == MaterialType::pbr ? pbr_emission(m, si, scene.textures, -ls.wi)
                                            : eval_color(m.radiance, scene.textures, si.p, si.uv);
    }
    ls.pdf *= pdf_solid;
    ls.delta = false;
    return true;
}

bool sample_envmap(const Scene& scene, Vec2 u, LightSample& ls) {
    float pdf_uv = 0, sin_theta = 0;
    const Vec2 uv = scene.envmap_distribution.sample(u, &pdf_uv);
    ls.wi = envmap_direction(scene.background.up, uv, &sin_theta);
    if (!(pdf_uv > 0) || !(sin_theta > 0)) return false;
    ls.li = envmap_radiance(scene.background, uv);
    ls.pdf *= pdf_uv / (2.0f * kPi * kPi * sin_theta);
    ls.distance = kInfinity;
    ls.delta = false;
    return true;
}

}  // namespace

OcclusionCache& shadow_cache(uint32_t index) {
    // Per thread: each keeps its own neighbouring shading points, and no entry is shared.
    thread_local std::array<OcclusionCache, 32> caches;
    return caches[index % caches.size()];
}

bool sample_light(const Scene& scene, const Vec3& p, float time, float u_select, Vec2 u, LightSample& ls) {
    if (scene.emitters.empty()) return false;
    float select_pdf = 0;
    const auto chosen = uint32_t(scene.emitter_distribution.sample_discrete(u_select, &select_pdf));
    const Emitter& e = scene.emitters[chosen];
    ls.pdf = select_pdf;
    ls.emitter = chosen;
    switch (e.kind) {
        case Emitter::Kind::point: {
            const LightDesc& l = scene.lights[e.index];
            const Vec3 d = l.position - p;
            const float dist2 = length_squared(d);
            if (!(dist2 > 0)) return false;
            ls.distance = std::sqrt(dist2);
            ls.wi = d / ls.distance;
            ls.li = l.intensity / dist2;  // inverse-square law
            ls.delta = true;
            return true;
        }
        case Emitter::Kind::directional: {
            const LightDesc& l = scene.lights[e.index];
            ls.wi = -normalize(l.direction);
            ls.distance = kInfinity;
            ls.li = l.irradiance;
            ls.delta = true;
            return true;
        }
        case Emitter::Kind::envmap:
            return sample_envmap(scene, u, ls);
        default:
            return sample_area_light(scene, e, p, time, u, ls);
    }
}

uint32_t emitter_of_hit(const Scene& scene, const Hit& hit) {
    if (hit.instance != kNoInstance) return scene.instanced_emitter(hit.instance, prim_index(hit.prim));
    const uint32_t i = prim_index(hit.prim);
    switch (prim_kind(hit.prim)) {
        case PrimKind::sphere:
            return scene.sphere_emitter.empty() ? kNoEmitter : scene.sphere_emitter[i];
        case PrimKind::triangle:
            return scene.triangle_emitter.empty() ? kNoEmitter : scene.triangle_emitter[i];
        case PrimKind::box:
            return scene.box_emitter.empty() ? kNoEmitter : scene.box_emitter[i];
        case PrimKind::plane:    // planes and quadrics are not light-sampled:
        case PrimKind::quadric:  // found by BSDF sampling alone (MIS weight 1)
            return kNoEmitter;
    }
    return kNoEmitter;
}

float area_light_pdf(const Scene& scene, uint32_t emitter, const Vec3& p, const Vec3& p_light,
                     const Vec3& n_light, float time) {
    const Emitter& e = scene.emitters[emitter];
    const float select = scene.emitter_distribution.pmf(emitter);
    if (e.kind == Emitter::Kind::sphere) {
        const Sphere& s = scene.spheres[e.index];
        const float dc2 = length_squared(s.center_at(time) - p), r2 = s.radius * s.radius;
        if (dc2 <= r2) return 0.0f;
        return select / (2.0f * kPi * cone_one_minus_cos(r2 / dc2));
    }
    float area = 0;
    if (e.kind == Emitter::Kind::triangle) {
        const TriangleSoup& t = scene.triangles;
        const Vec3& p0 = t.positions[t.indices[3 * e.index]];
        area = 0.5f * length(cross(t.positions[t.indices[3 * e.index + 1]] - p0,
                                   t.positions[t.indices[3 * e.index + 2]] - p0));
    } else if (e.kind == Emitter::Kind::instanced_triangle) {
        const InstancedEmitter& t = scene.instanced_emitters[e.index];
        area = 0.5f * length(cross(t.p1 - t.p0, t.p2 - t.p0));
    } else if (e.kind == Emitter::Kind::box) {
        area = scene.boxes[e.index].box.surface_area();
    }
    const Vec3 d = p_light - p;
    const float dist2 = length_squared(d);
    const float cos_l = std::abs(dot(n_light, d)) / std::sqrt(dist2);
    if (!(cos_l > 0) || !(area > 0)) return 0.0f;
    return select * dist2 / (cos_l * area);
}

float envmap_light_pdf(const Scene& scene, const Vec3& dir) {
    if (scene.envmap_emitter == kNoEmitter) return 0.0f;
    const Vec2 uv = envmap_uv(scene.background.up, dir);
    const float sin_theta = std::sin(kPi * uv.y);
    if (!(sin_theta > 0)) return 0.0f;
    return scene.emitter_distribution.pmf(scene.envmap_emitter) * scene.envmap_distribution.pdf(uv) /
           (2.0f * kPi * kPi * sin_theta);
}

Ray shadow_ray(const Vec3& p, const Vec3& ng, const LightSample& ls, float time) {
    const Vec3 origin = offset_ray_origin(p, dot(ls.wi, ng) >= 0 ? ng : -ng);
    const float tmax = std::isinf(ls.distance) ? kInfinity : ls.distance * (1.0f - kShadowEpsilon);
    return Ray{origin, ls.wi, 0.0f, tmax, time};
}

}  // namespace sahara
