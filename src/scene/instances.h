#pragma once
/// The instance level of a two-level BVH: prototypes (groups of meshes, each a
/// small Scene of its own with its own Accelerator, the bottom-level tree shared by
/// all its instances) and a top-level binary BVH over the instances' world bounds.
/// A ray reaching an instance leaf is moved into the prototype's space (the
/// direction is not renormalised, so t is the same in both spaces), traced there,
/// and the hit records the instance; interact() shades in the prototype's space and
/// moves the result back (normals by the inverse transpose).
/// A Scene owns one only when its description has instances: flat scenes keep
/// their single tree and pay nothing.
#include <cstdint>
#include <vector>

#include "accel/bvh.h"
#include "math/transform.h"
#include "scene/scene.h"

namespace sahara {

/// A 3x4 affine transform in float, for moving rays (12 multiply-adds).
struct Affine3f {
    float m[3][4];
    explicit Affine3f(const Mat4& d);
    Vec3 point(const Vec3& p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    Vec3 vector(const Vec3& v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
};

class InstanceSet {
   public:
    /// Builds one bottom-level Scene per prototype of `desc` (its meshes, with the
    /// scene's materials and textures) and the top-level tree over desc.instances.
    explicit InstanceSet(const SceneDesc& desc);

    /// Nearest instanced hit with t in (ray.tmin, ray.tmax); on a hit, ray.tmax
    /// becomes hit.t and hit.instance names the instance.
    bool intersect(Ray& ray, Hit& hit) const;
    bool occluded(const Ray& ray) const;
    /// Shading data of a hit with hit.instance set, in world space.
    SurfaceInteraction interact(const Ray& ray, const Hit& hit) const;

    /// World bounds over the shutter (moving instances: both ends of their path).
    Bounds3 bounds() const { return bounds_; }
    /// Whether an instance moves (has a velocity); motion blur needs the ray times then.
    bool has_motion() const { return moving_; }
    size_t instance_count() const { return instances_.size(); }
    /// The bottom-level scene an instance places, and where: for light sampling.
    const Scene& prototype_of(uint32_t instance) const { return prototypes_[instances_[instance].prototype]; }
    uint32_t prototype_index(uint32_t instance) const { return instances_[instance].prototype; }
    const Mat4& world_from_object(uint32_t instance) const { return instances_[instance].world_from_object; }
    Vec3 velocity(uint32_t instance) const { return instances_[instance].velocity; }
    /// The top-level tree (its leaves hold instance indices), for reports.
    const Bvh& top_level() const { return top_; }
    size_t prototype_count() const { return prototypes_.size(); }
    const Scene& prototype(size_t i) const { return prototypes_[i]; }
    /// Triangles stored once per prototype (what memory holds)...
    size_t unique_triangle_count() const;
    /// ... and as drawn (what a flattened scene would hold).
    size_t instanced_triangle_count() const;
    /// Bytes of the top-level tree, the instances and every prototype's tree.
    size_t bytes() const;

   private:
    struct Instance {
        Affine3f object_from_world;  ///< moves rays into the prototype's space
        uint32_t prototype;
        Vec3 velocity;           ///< world-space motion: the ray origin moves back by velocity * time
        Mat4 world_from_object;  ///< moves shading data back (double: once per hit)
        /// The ray in the prototype's space at the ray's time.
        Ray local_ray(const Ray& ray, float tmax) const {
            return {object_from_world.point(ray.origin - velocity * ray.time),
                    object_from_world.vector(ray.dir), ray.tmin, tmax, ray.time};
        }
    };
    template <bool kAnyHit>
    bool trace(Ray& ray, Hit& hit) const;

    std::vector<Scene> prototypes_;
    std::vector<Instance> instances_;
    Bvh top_;  ///< leaves hold instance indices
    Bounds3 bounds_;
    bool moving_ = false;
};

}  // namespace sahara
