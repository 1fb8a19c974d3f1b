#pragma once
/// Infinite plane: unbounded, so it never enters the BVH; Scene tests its
/// planes one by one beside the tree.
#include <cstdint>
#include <optional>

#include "geometry/shape.h"
#include "math/bounds.h"
#include "math/ray.h"

namespace sahara {

struct Plane {
    static constexpr bool kBounded = false;

    Vec3 point, normal;  ///< normal: unit
    uint32_t material = 0;

    /// All of space: a plane has no finite box.
    Bounds3 bounds() const { return unbounded_bounds(); }
    /// The crossing in (ray.tmin, ray.tmax); a ray parallel to the plane misses.
    std::optional<ShapeHit> intersect(const Ray& ray) const {
        const float denom = dot(normal, ray.dir);
        if (denom == 0.0f) return std::nullopt;
        const float t = dot(point - ray.origin, normal) / denom;
        if (!(t > ray.tmin && t < ray.tmax)) return std::nullopt;
        return ShapeHit{t};
    }
    bool occluded(const Ray& ray) const { return intersect(ray).has_value(); }
};
static_assert(Shape<Plane>);

}  // namespace sahara
