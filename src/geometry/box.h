#pragma once
/// Solid axis-aligned box primitive, tested with Kay and Kajiya's slabs.
#include <cstdint>
#include <optional>
#include <utility>

#include "geometry/shape.h"
#include "math/bounds.h"
#include "math/ray.h"

namespace sahara {

struct Box {
    static constexpr bool kBounded = true;

    Bounds3 box;
    uint32_t material = 0;

    Bounds3 bounds() const { return box; }
    /// Nearest boundary crossing in (ray.tmin, ray.tmax): the entry point, or, for an
    /// origin inside the box, the exit point. A zero direction component with the origin
    /// exactly on a slab plane counts as inside that slab.
    std::optional<ShapeHit> intersect(const Ray& ray) const {
        float t0 = -kInfinity, t1 = kInfinity;
        for (int a = 0; a < 3; ++a) {
            const float inv = 1.0f / ray.dir[a];
            float tn = (box.lo[a] - ray.origin[a]) * inv;
            float tf = (box.hi[a] - ray.origin[a]) * inv;
            if (tn > tf) std::swap(tn, tf);
            // A NaN slab distance (0 * inf: origin on the slab plane) leaves the interval as it is.
            t0 = tn > t0 ? tn : t0;
            t1 = tf < t1 ? tf : t1;
        }
        if (!(t0 <= t1)) return std::nullopt;
        if (t0 > ray.tmin && t0 < ray.tmax) return ShapeHit{t0};
        if (t1 > ray.tmin && t1 < ray.tmax) return ShapeHit{t1};
        return std::nullopt;
    }
    bool occluded(const Ray& ray) const { return intersect(ray).has_value(); }
};
static_assert(Shape<Box>);

}  // namespace sahara
