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

    Bounds3 bounds() const { return bounds_; }
    size_t instance_count() const { return instances_.size(); }
    size_t prototype_count() const { return prototypes_.size(); }
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
        Mat4 world_from_object;  ///< moves shading data back (double: once per hit)
    };
    template <bool kAnyHit>
    bool trace(Ray& ray, Hit& hit) const;

    std::vector<Scene> prototypes_;
    std::vector<Instance> instances_;
    Bvh top_;  ///< leaves hold instance indices
    Bounds3 bounds_;
};

}  // namespace sahara
