#pragma once
/// Self-intersection-free ray origins. A hit point computed in float lies
/// slightly above or below the true surface; spawning a new ray from it can
/// re-hit the same surface at t ~ 0 ("acne"). The rounding error of a float
/// point is at most half an ulp per coordinate, and every coordinate's error
/// projects onto the normal, so the bound that matters is set by the largest
/// coordinate: the origin is pushed along the geometric normal by a distance
/// relative to max|p_i| (about 8-16 ulps of it), with a tiny absolute floor
/// near the world origin.
///
/// This replaces the per-coordinate ulp offsets of Waechter and Binder, "A Fast
/// and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6):
/// with those, a coordinate of large magnitude but small normal component
/// (|n_i| < 1/256 gives no offset at all) kept its rounding error while a
/// near-zero coordinate moved only by a fixed absolute 2^-16, so the radius-1e6
/// ground sphere 1e5 units from the origin showed acne; and their 256-ulp
/// offsets (2 units at 1e5) were large enough to start rays inside a
/// neighbouring object, so a scene moved away from the origin rendered darker.
#include <cmath>

#include "math/vec3.h"

namespace sahara {

namespace spawn_detail {
/// Push distance per unit of max|p_i|: 2^-20 is 8 to 16 ulps of that coordinate.
inline constexpr float kRelative = 1.0f / 1048576.0f;
/// Smallest push: covers the absolute error of points computed from unit-scale
/// data (e.g. triangle vertices) that happen to lie near the origin.
inline constexpr float kMinPush = 1.0f / 2097152.0f;
}  // namespace spawn_detail

/// Moves p off the surface to the side that `n` (the geometric normal, unit,
/// pointing to the side the new ray leaves towards) points to.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
    const float push = std::max(spawn_detail::kRelative * max_component(abs(p)), spawn_detail::kMinPush);
    return p + n * push;
}

}  // namespace sahara
