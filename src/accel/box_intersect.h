#pragma once
/// Ray against a solid axis-aligned box primitive (Kay and Kajiya slabs).
#include "accel/bvh_traverse.h"
#include "math/bounds.h"
#include "math/ray.h"

namespace sahara {

/// Nearest boundary crossing of `ray` with `box` in (tmin, tmax): the entry
/// point, or, for an origin inside the box, the exit point. A zero direction
/// component with the origin exactly on a slab plane counts as inside that slab.
inline bool intersect_box(const Ray& ray, const Bounds3& box, float tmin, float tmax, float& t_hit) {
    float t0 = -kInfinity, t1 = kInfinity;
    for (int a = 0; a < 3; ++a) {
        const float inv = 1.0f / ray.dir[a];
        float tn = (box.lo[a] - ray.origin[a]) * inv;
        float tf = (box.hi[a] - ray.origin[a]) * inv;
        if (tn > tf) std::swap(tn, tf);
        t0 = max_ignore_nan(t0, tn);
        t1 = min_ignore_nan(t1, tf);
    }
    if (!(t0 <= t1)) return false;
    if (t0 > tmin && t0 < tmax)
        t_hit = t0;
    else if (t1 > tmin && t1 < tmax)
        t_hit = t1;
    else
        return false;
    return true;
}

}  // namespace sahara
