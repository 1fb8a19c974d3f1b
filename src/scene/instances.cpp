#include "scene/instances.h"

#include "accel/bvh_traverse.h"
#include "scene/accelerator.h"

namespace sahara {

Affine3f::Affine3f(const Mat4& d) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = float(d.m[size_t(r)][size_t(c)]);
}

namespace {

/// The prototype's meshes alone, with the scene's materials and textures (material
/// ids stay valid) and build settings: build_scene makes its bottom-level tree.
SceneDesc prototype_desc(const SceneDesc& desc, const PrototypeDesc& proto) {
    SceneDesc sub;
    sub.source = desc.source + ": " + proto.name;
    sub.render = desc.render;
    sub.camera = desc.camera;
    sub.materials = desc.materials;
    sub.textures = desc.textures;
    for (uint32_t m : proto.meshes) sub.meshes.push_back(desc.meshes[m]);
    return sub;
}

/// World bounds of an object-space box: the box of its eight transformed corners.
Bounds3 transformed_bounds(const Bounds3& b, const Mat4& m) {
    Bounds3 out;
    if (!(b.lo.x <= b.hi.x)) return out;
    for (int k = 0; k < 8; ++k) {
        const Vec3 corner(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
        out.extend(m.apply_point(corner));
    }
    // apply_point rounds to float: widen by a few ulps so no hit falls outside.
    const Vec3 pad = (abs(out.lo) + abs(out.hi) + out.extent()) * 1e-6f;
    return {out.lo - pad, out.hi + pad};
}

}  // namespace

InstanceSet::InstanceSet(const SceneDesc& desc) {
    prototypes_.reserve(desc.prototypes.size());
    for (const PrototypeDesc& p : desc.prototypes)
        prototypes_.push_back(build_scene(prototype_desc(desc, p)));
    instances_.reserve(desc.instances.size());
    std::vector<Bounds3> boxes;
    std::vector<Vec3> centers;
    const float t0 = desc.camera.shutter_open, t1 = desc.camera.shutter_close;
    for (const InstanceDesc& in : desc.instances) {
        instances_.push_back({Affine3f(affine_inverse(in.world_from_object)), in.prototype, in.velocity,
                              in.world_from_object});
        moving_ |= in.velocity != Vec3(0.0f);
        Bounds3 b = transformed_bounds(prototypes_[in.prototype].bounds(), in.world_from_object);
        if (in.velocity != Vec3(0.0f) && b.lo.x <= b.hi.x) {
            // A translation sweeps the box between its two ends (both, for any shutter order).
            const Bounds3 start{b.lo + in.velocity * t0, b.hi + in.velocity * t0};
            b = Bounds3{b.lo + in.velocity * t1, b.hi + in.velocity * t1};
            b.extend(start);
        }
        boxes.push_back(b);
        centers.push_back(b.lo.x <= b.hi.x ? b.center() : Vec3(0.0f));
        bounds_.extend(b);
    }
    // An instance test is a whole bottom-level traversal: many times a triangle's
    // cost, so leaves hold one or two instances.
    BvhBuildParams params;
    params.intersection_cost = 8.0f;
    params.max_leaf_size = 2;
    top_ = build_bvh(BvhBuildInput{boxes, centers}, BvhBuilder::binned, params);
}

template <bool kAnyHit>
bool InstanceSet::trace(Ray& ray, Hit& hit) const {
    BvhRay bray(ray);
    NoTraversalCounters counters;
    auto leaf = [&](uint32_t first, uint32_t count, float& tmax) {
        bool found = false;
        for (uint32_t s = first; s < first + count; ++s) {
            const uint32_t id = top_.prim_indices[s];
            const Instance& in = instances_[id];
            const Accelerator* accel = prototypes_[in.prototype].accelerator();
            // Not renormalised: t means the same distance along the ray in both spaces.
            Ray local = in.local_ray(ray, tmax);
            if constexpr (kAnyHit) {
                if (accel->occluded(local)) return true;
            } else {
                Hit h;
                if (accel->intersect(local, h)) {
                    tmax = h.t;
                    hit = h;
                    hit.instance = id;
                    found = true;
                }
            }
        }
        return found;
    };
    const bool found = traverse_bvh<kAnyHit>(top_, bray, leaf, counters);
    if (found && !kAnyHit) ray.tmax = hit.t;
    return found;
}

bool InstanceSet::intersect(Ray& ray, Hit& hit) const { return trace<false>(ray, hit); }

bool InstanceSet::occluded(const Ray& ray) const {
    Ray r = ray;
    Hit h;
    return trace<true>(r, h);
}

SurfaceInteraction InstanceSet::interact(const Ray& ray, const Hit& hit) const {
    const Instance& in = instances_[hit.instance];
    const Ray local = in.local_ray(ray, ray.tmax);
    Hit h = hit;
    h.instance = kNoInstance;
    // Oriented against the local ray: the inverse transpose keeps the sign of
    // dot(n, dir), so the orientation holds in world space too.
    SurfaceInteraction si = prototypes_[in.prototype].interact(local, h);
    const Mat4& m = in.world_from_object;
    si.p = m.apply_point(si.p) + in.velocity * ray.time;
    si.ng = m.apply_normal(si.ng);
    si.ns = m.apply_normal(si.ns);
    if (si.tangent != Vec3(0.0f)) {
        si.tangent = m.apply_vector(si.tangent);
        // A mirror flips the bitangent cross(n, t) against the uv direction (as transform_mesh does).
        if (m.determinant3() < 0) si.tangent_sign = -si.tangent_sign;
    }
    return si;
}

size_t InstanceSet::unique_triangle_count() const {
    size_t n = 0;
    for (const Scene& p : prototypes_) n += p.triangles.size();
    return n;
}

size_t InstanceSet::instanced_triangle_count() const {
    size_t n = 0;
    for (const Instance& in : instances_) n += prototypes_[in.prototype].triangles.size();
    return n;
}

size_t InstanceSet::bytes() const {
    size_t n = top_.bytes() + instances_.size() * sizeof(Instance);
    for (const Scene& p : prototypes_)
        if (p.accelerator()) n += p.accelerator()->bytes();
    return n;
}

}  // namespace sahara
