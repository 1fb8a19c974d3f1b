#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <stdexcept>

#include "scene/accelerator.h"
#include "scene/instances.h"
#include "scene/tangents.h"
#include "accel/packet.h"
#include "accel/simd_path.h"
#include "base/counters.h"

namespace sahara {

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

size_t Scene::primitive_count() const {
    return spheres.size() + triangles.size() + boxes.size() + planes.size() + quadrics.size();
}

void Scene::build_accelerator() {
    AcceleratorOptions options;
    options.builder = render.bvh_builder;
    options.expected_rays = expected_render_rays();
    options.layout = render.bvh_layout;
    accel_ = std::make_unique<Accelerator>(*this, options);
    bounds_ = accel_->bounds();
    if (instances_) bounds_.extend(instances_->bounds());
}

std::vector<const Scene*> Scene::prototypes() const {
    std::vector<const Scene*> out;
    for (size_t i = 0; instances_ && i < instances_->prototype_count(); ++i)
        out.push_back(&instances_->prototype(i));
    return out;
}

size_t Scene::instance_level_bytes() const { return instances_ ? instances_->bytes() : 0; }

void Scene::set_instances(std::unique_ptr<InstanceSet> instances) { instances_ = std::move(instances); }

namespace {

/// Unbounded planes (Plane::kBounded is false) live outside the tree and are tested linearly.
bool intersect_planes(const std::vector<Plane>& planes, Ray& ray, Hit& hit) {
    static_assert(!Plane::kBounded);
    bool found = false;
    for (uint32_t i = 0; i < planes.size(); ++i) {
        const std::optional<ShapeHit> h = planes[i].intersect(ray);
        if (!h) continue;
        ray.tmax = h->t;
        hit = Hit{h->t, make_prim_id(PrimKind::plane, i), 0, 0};
        found = true;
    }
    return found;
}

}  // namespace

bool Scene::intersect(Ray& ray, Hit& hit) const {
    count_ray(RayKind::closest_hit);
    bool found = accel_ ? accel_->intersect(ray, hit) : false;
    if (instances_) found |= instances_->intersect(ray, hit);
    found |= intersect_planes(planes, ray, hit);
    return found;
}

void Scene::intersect_packet(RayPacket& packet, HitPacket& hits) const {
    if (instances_) throw std::logic_error("Scene::intersect_packet: the scene has instances");
    if (accel_) {
        accel_->intersect_packet(packet, hits);
    } else {
        for (int i = 0; i < kPacketSize; ++i) hits.prim[i] = kNoPrim, hits.t[i] = kInfinity;
    }
    for (uint32_t m = packet.active; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        count_ray(RayKind::closest_hit);
        if (planes.empty()) continue;
        Ray r = packet.ray(i);
        Hit h = hits.hit(i);
        if (intersect_planes(planes, r, h)) {
            hits.t[i] = h.t, hits.prim[i] = h.prim, hits.u[i] = h.u, hits.v[i] = h.v;
            packet.tmax[i] = h.t;
        }
    }
}

bool Scene::occluded(const Ray& ray) const {
    count_ray(RayKind::shadow);
    return (accel_ && accel_->occluded(ray)) || occluded_outside_tree(ray);
}

bool Scene::occluded(const Ray& ray, OcclusionCache& cache) const {
    count_ray(RayKind::shadow);
    return (accel_ && accel_->occluded(ray, cache)) || occluded_outside_tree(ray);
}

bool Scene::occluded_outside_tree(const Ray& ray) const {
    if (instances_ && instances_->occluded(ray)) return true;
    return std::any_of(planes.begin(), planes.end(), [&](const Plane& pl) { return pl.occluded(ray); });
}

uint64_t Scene::traversal_steps(const Ray& ray) const {
    if (!accel_) return 0;
    TraversalCounters counters;
    Ray r = ray;
    Hit hit;
    accel_->intersect_counted(r, hit, counters);
    return counters.nodes_visited + counters.prims_tested;
}

bool Scene::packets_pay_off() const {
    if (!accel_ || instances_ || !layout_has_blocks(accel_->layout()) || !accel_->uses_tree() ||
        accel_->has_cutouts())
        return false;
    return active_simd_path() != SimdPath::sse2;
}

size_t Scene::cutout_triangle_count() const {
    return accel_ && accel_->has_cutouts() ? accel_->alpha_filter().size() : 0;
}

}  // namespace sahara

namespace sahara {

namespace {

Vec2 sphere_uv(const Vec3& n) {
    // Longitude around z, latitude from +z: the scene format has no fixed up,
    // so spherical UVs follow the world z axis.
    const float u = 0.5f + std::atan2(n.y, n.x) * (0.5f * std::numbers::inv_pi_v<float>);
    const float v = 0.5f + std::asin(std::clamp(n.z, -1.0f, 1.0f)) * std::numbers::inv_pi_v<float>;
    return {u, v};
}

/// The glTF material's inputs: second UV set, vertex colour, tangent.
void interact_triangle_attributes(const TriangleSoup& soup, uint32_t i0, uint32_t i1, uint32_t i2, float b0,
                                  float b1, float b2, SurfaceInteraction& si) {
    if (!soup.uvs1.empty()) {
        const Vec2 &a = soup.uvs1[i0], &b = soup.uvs1[i1], &c = soup.uvs1[i2];
        si.uv1 = {a.x * b0 + b.x * b1 + c.x * b2, a.y * b0 + b.y * b1 + c.y * b2};
    }
    if (!soup.colors.empty()) si.color = soup.colors[i0] * b0 + soup.colors[i1] * b1 + soup.colors[i2] * b2;
    if (!soup.tangents.empty()) {
        const auto &a = soup.tangents[i0], &b = soup.tangents[i1], &c = soup.tangents[i2];
        si.tangent = Vec3(a[0], a[1], a[2]) * b0 + Vec3(b[0], b[1], b[2]) * b1 + Vec3(c[0], c[1], c[2]) * b2;
        si.tangent_sign = a[3] < 0 ? -1.0f : 1.0f;
    }
}

void interact_triangle(const TriangleSoup& soup, uint32_t i, const Hit& hit, SurfaceInteraction& si) {
    const uint32_t i0 = soup.indices[3 * i], i1 = soup.indices[3 * i + 1], i2 = soup.indices[3 * i + 2];
    const float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
    const Vec3 &p0 = soup.positions[i0], &p1 = soup.positions[i1], &p2 = soup.positions[i2];
    // Barycentric interpolation is more accurate than origin + t * dir far from the origin.
    si.p = p0 * b0 + p1 * b1 + p2 * b2;
    si.ng = normalize(cross(p1 - p0, p2 - p0));
    si.ns = si.ng;
    if (!soup.normals.empty()) {
        Vec3 n = soup.normals[i0] * b0 + soup.normals[i1] * b1 + soup.normals[i2] * b2;
        if (length_squared(n) > 0) si.ns = normalize(n);
    }
    if (!soup.uvs.empty()) {
        const Vec2 &a = soup.uvs[i0], &b = soup.uvs[i1], &c = soup.uvs[i2];
        si.uv = {a.x * b0 + b.x * b1 + c.x * b2, a.y * b0 + b.y * b1 + c.y * b2};
    } else {
        si.uv = {b1, b2};
    }
    interact_triangle_attributes(soup, i0, i1, i2, b0, b1, b2, si);
    si.material = soup.material[i];
}

/// Whether a mesh uses a material that needs tangents (normal-mapped or anisotropic).
bool needs_tangents(const SceneDesc& desc, const TriangleMesh& m) {
    auto mapped = [&](uint32_t id) {
        if (id >= desc.materials.size()) return false;
        const MaterialDesc& d = desc.materials[id];
        return d.normal_texture >= 0 || d.layers.clearcoat_normal_texture >= 0 || d.anisotropy > 0;
    };
    if (m.material_ids.empty()) return mapped(m.material);
    return std::any_of(m.material_ids.begin(), m.material_ids.end(), mapped);
}

/// Appends `values` for a mesh, or `fill` per position when it has none; the
/// whole array stays empty while no mesh has any.
template <class T>
void append_attribute(std::vector<T>& out, const std::vector<T>& values, size_t positions, size_t total,
                      const T& fill) {
    if (values.size() == positions)
        out.insert(out.end(), values.begin(), values.end());
    else
        out.resize(total, fill);
}

/// The meshes' second UV set, vertex colours and tangents, merged in the order
/// build_scene merges positions (tangents generated where a material needs them).
void merge_material_inputs(const SceneDesc& desc, TriangleSoup& soup) {
    bool any_uv1 = false, any_colors = false, any_alphas = false, any_tangents = false;
    std::vector<std::vector<std::array<float, 4>>> tangents(desc.meshes.size());
    for (size_t k = 0; k < desc.meshes.size(); ++k) {
        const TriangleMesh& m = desc.meshes[k];
        any_uv1 |= !m.uvs1.empty();
        any_colors |= !m.colors.empty();
        any_alphas |= !m.color_alphas.empty();
        if (m.tangents.size() == m.positions.size() && !m.tangents.empty())
            tangents[k] = m.tangents;
        else if (needs_tangents(desc, m))
            tangents[k] = generate_tangents(m);
        any_tangents |= !tangents[k].empty();
    }
    size_t total = 0;
    for (size_t k = 0; k < desc.meshes.size(); ++k) {
        const size_t n = desc.meshes[k].positions.size();
        total += n;
        if (any_uv1) append_attribute(soup.uvs1, desc.meshes[k].uvs1, n, total, Vec2{0, 0});
        if (any_colors) append_attribute(soup.colors, desc.meshes[k].colors, n, total, Rgb(1.0f));
        if (any_alphas) append_attribute(soup.color_alphas, desc.meshes[k].color_alphas, n, total, 1.0f);
        if (any_tangents)
            append_attribute(soup.tangents, tangents[k], n, total, std::array<float, 4>{0, 0, 0, 1});
    }
}

Vec3 box_normal(const Bounds3& b, const Vec3& p) {
    // The face whose plane is closest to p, relative to the box size.
    const Vec3 e = b.extent() * 0.5f, c = b.center(), d = p - c;
    int axis = 0;
    float best = -1;
    for (int k = 0; k < 3; ++k) {
        float r = e[k] > 0 ? std::abs(d[k]) / e[k] : 1.0f;
        if (r > best) {
            best = r;
            axis = k;
        }
    }
    Vec3 n(0.0f);
    n[axis] = d[axis] >= 0 ? 1.0f : -1.0f;
    return n;
}

void interact_sphere(const Sphere& s, const Ray& ray, const Hit& hit, bool want_uv, SurfaceInteraction& si) {
    const Vec3 c = s.center_at(ray.time);
    // Reproject onto the surface: removes the error of origin + t * dir.
    const Vec3d d = Vec3d(ray.origin) + Vec3d(ray.dir) * double(hit.t) - Vec3d(c);
    const Vec3d n = d / length(d);
    si.p = Vec3(Vec3d(c) + n * double(s.radius));
    si.ng = si.ns = Vec3(n);
    if (want_uv) si.uv = sphere_uv(Vec3(n));
    si.material = s.material;
}

void interact_box(const Box& b, const Ray& ray, const Hit& hit, SurfaceInteraction& si) {
    si.p = ray.at(hit.t);
    si.ng = si.ns = box_normal(b.box, si.p);
    // Snap onto the face: textures keyed on position (checkers) must not
    // see the hit wander to either side of it.
    const int axis = max_dimension(abs(si.ng));
    si.p[axis] = si.ng[axis] > 0 ? b.box.hi[axis] : b.box.lo[axis];
    si.uv = {0, 0};
    si.material = b.material;
}

}  // namespace

/// The runtime quadric of a parsed description: the description's local frame
/// already holds the placement, so the named forms sit at the origin along +z.
Quadric make_quadric(const QuadricDesc& d) {
    const Vec3 o(0, 0, 0), z(0, 0, 1);
    Quadric q;
    switch (d.type) {
        case QuadricDesc::Type::ellipsoid:
            q = make_ellipsoid(o, d.radii, d.world_from_local);
            break;
        case QuadricDesc::Type::cylinder:
            q = make_cylinder(o, z, d.radius, d.height, d.capped, d.world_from_local);
            break;
        case QuadricDesc::Type::cone:
            q = make_cone(o, z, d.angle, d.height, d.capped, d.world_from_local);
            break;
        case QuadricDesc::Type::paraboloid:
            q = make_paraboloid(o, z, d.radius, d.height, d.world_from_local);
            break;
        case QuadricDesc::Type::hyperboloid:
            q = make_hyperboloid(o, z, d.radius, d.waist, d.height, d.world_from_local);
            break;
        case QuadricDesc::Type::general:
            q = make_general_quadric(d.coefficients, d.local_bounds, d.world_from_local);
            break;
    }
    q.material = d.material;
    return q;
}

SurfaceInteraction Scene::interact(const Ray& ray, const Hit& hit) const {
    if (hit.instance != kNoInstance) return instances_->interact(ray, hit);
    SurfaceInteraction si;
    const uint32_t idx = prim_index(hit.prim);
    switch (prim_kind(hit.prim)) {
        case PrimKind::triangle:
            interact_triangle(triangles, idx, hit, si);
            break;
        case PrimKind::sphere:
            // uv feeds image textures only (eval_color): without any, skip the atan2 and asin.
            interact_sphere(spheres[idx], ray, hit, !textures.empty(), si);
            break;
        case PrimKind::box:
            interact_box(boxes[idx], ray, hit, si);
            break;
        case PrimKind::quadric: {
            // Hit has no part field: hit_at finds the part (side or cap) again.
            const Quadric& q = quadrics[idx];
            const QuadricSurface qs = q.surface(ray, q.hit_at(ray, hit.t));
            si.p = qs.p;
            si.ng = si.ns = qs.n;
            si.uv = qs.uv;
            si.material = q.material;
            break;
        }
        case PrimKind::plane: {
            const Plane& pl = planes[idx];
            si.p = ray.at(hit.t);
            // Project onto the plane (exact for axis-aligned planes), as for boxes.
            si.p -= pl.normal * dot(si.p - pl.point, pl.normal);
            si.ng = si.ns = pl.normal;
            si.uv = {0, 0};
            si.material = pl.material;
            break;
        }
    }
    // Orient both normals against the incoming ray; remember which side was hit.
    si.front_face = dot(si.ng, ray.dir) < 0;
    if (!si.front_face) {
        si.ng = -si.ng;
        si.ns = -si.ns;
    }
    if (dot(si.ns, si.ng) < 0) si.ns = si.ng;
    return si;
}

namespace {

/// Everything but the trees: the runtime copies of the description's primitives.
void fill_scene(const SceneDesc& desc, Scene& scene) {
    scene.source = desc.source;
    scene.render = desc.render;
    scene.camera = desc.camera;
    scene.background = desc.background;
    scene.materials = desc.materials;
    if (scene.materials.empty()) scene.materials.push_back(default_material());
    scene.textures = desc.textures;
    scene.lights = desc.lights;
    for (const SphereDesc& s : desc.spheres)
        scene.spheres.push_back({s.center, s.radius, s.velocity, s.material});
    for (const PlaneDesc& p : desc.planes) scene.planes.push_back({p.point, normalize(p.normal), p.material});
    for (const QuadricDesc& q : desc.quadrics) scene.quadrics.push_back(make_quadric(q));
    for (const BoxDesc& b : desc.boxes)
        scene.boxes.push_back({Bounds3{min(b.lo, b.hi), max(b.lo, b.hi)}, b.material});

    bool any_normals = false, any_uvs = false;
    for (const TriangleMesh& m : desc.meshes) {
        any_normals |= !m.normals.empty();
        any_uvs |= !m.uvs.empty();
    }
    TriangleSoup& soup = scene.triangles;
    merge_material_inputs(desc, soup);
    for (const TriangleMesh& m : desc.meshes) {
        const uint32_t base = uint32_t(soup.positions.size());
        soup.positions.insert(soup.positions.end(), m.positions.begin(), m.positions.end());
        // Meshes without normals get zero normals: interact() falls back to the geometric one.
        if (any_normals) {
            if (m.normals.empty())
                soup.normals.resize(soup.positions.size(), Vec3(0.0f));
            else
                soup.normals.insert(soup.normals.end(), m.normals.begin(), m.normals.end());
        }
        if (any_uvs) {
            if (m.uvs.empty())
                soup.uvs.resize(soup.positions.size(), Vec2{0, 0});
            else
                soup.uvs.insert(soup.uvs.end(), m.uvs.begin(), m.uvs.end());
        }
        for (uint32_t idx : m.indices) soup.indices.push_back(base + idx);
        for (size_t t = 0; t < m.triangle_count(); ++t)
            soup.material.push_back(m.material_ids.empty() ? m.material : m.material_ids[t]);
    }
}

/// The description without its prototypes' meshes and its instances: what the flat tree holds.
SceneDesc uninstanced_part(const SceneDesc& desc) {
    std::vector<bool> in_prototype(desc.meshes.size(), false);
    for (const PrototypeDesc& p : desc.prototypes)
        for (uint32_t m : p.meshes) in_prototype[m] = true;
    SceneDesc flat;
    flat.source = desc.source;
    flat.render = desc.render;
    flat.camera = desc.camera;
    flat.background = desc.background;
    flat.materials = desc.materials;
    flat.textures = desc.textures;
    flat.spheres = desc.spheres;
    flat.planes = desc.planes;
    flat.boxes = desc.boxes;
    flat.quadrics = desc.quadrics;
    flat.lights = desc.lights;
    for (size_t m = 0; m < desc.meshes.size(); ++m)
        if (!in_prototype[m]) flat.meshes.push_back(desc.meshes[m]);
    return flat;
}

}  // namespace

Scene build_scene(const SceneDesc& desc) {
    Scene scene;
    if (desc.prototypes.empty()) {
        fill_scene(desc, scene);  // the flat scene as it always was: nothing copied
    } else {
        fill_scene(uninstanced_part(desc), scene);
        if (!desc.instances.empty()) scene.set_instances(std::make_unique<InstanceSet>(desc));
    }
    scene.build_accelerator();
    scene.prepare_lighting(false);
    return scene;
}

}  // namespace sahara
