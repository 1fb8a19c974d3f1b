#pragma once
/// Self-intersection-free ray origins. A hit point computed in float lies
/// slightly above or below the true surface; spawning a new ray from it can
/// re-hit the same surface at t ~ 0 ("acne"). Following Waechter and Binder,
/// "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems,
/// ch. 6), the origin is pushed along the geometric normal by a fixed number of
/// ulps of each coordinate (scale-aware: the offset grows with |p|), with a tiny
/// absolute offset near the origin where ulps vanish.
#include <bit>
#include <cmath>
#include <cstdint>

#include "math/vec3.h"

namespace sahara {

namespace spawn_detail {
inline constexpr float kOrigin = 1.0f / 32.0f;
inline constexpr float kFloatScale = 1.0f / 65536.0f;
inline constexpr float kIntScale = 256.0f;

inline float offset_coord(float p, float n) {
    int32_t of_i = int32_t(kIntScale * n);
    int32_t bits = std::bit_cast<int32_t>(p);
    float p_i = std::bit_cast<float>(bits + ((p < 0) ? -of_i : of_i));
    return std::abs(p) < kOrigin ? p + kFloatScale * n : p_i;
}
}  // namespace spawn_detail

/// Moves p off the surface to the side that `n` (the geometric normal, unit,
/// pointing to the side the new ray leaves towards) points to.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
    return {spawn_detail::offset_coord(p.x, n.x), spawn_detail::offset_coord(p.y, n.y),
            spawn_detail::offset_coord(p.z, n.z)};
}

}  // namespace sahara
