#pragma once
/// The lat-long (equirectangular) mapping of environment images: one mapping
/// for the renderer that samples them and the code that generates them.
#include <cmath>

#include "math/sampling.h"

namespace sahara {

/// Lat-long coordinates (u, v) in [0,1)^2 of direction `dir` around `up`:
/// u from the azimuth, v = 0 at the zenith (the image top).
inline Vec2 envmap_uv(const Vec3& up, const Vec3& dir) {
    const Frame f(normalize(up));
    const Vec3 l = f.to_local(normalize(dir));
    const float phi = std::atan2(l.y, l.x);
    // atan2 rather than acos: accurate near the poles, where acos(z) loses theta.
    const float theta = std::atan2(std::sqrt(l.x * l.x + l.y * l.y), l.z);
    return {phi * (0.5f * kInvPi) + 0.5f, theta * kInvPi};
}

/// The unit direction of lat-long coordinates (u, v) (inverse of envmap_uv);
/// *sin_theta receives the Jacobian factor of the mapping.
inline Vec3 envmap_direction(const Vec3& up, Vec2 uv, float* sin_theta) {
    const float phi = 2.0f * kPi * (uv.x - 0.5f), theta = kPi * uv.y;
    const float st = std::sin(theta);
    *sin_theta = st;
    return Frame(normalize(up)).to_world(Vec3(st * std::cos(phi), st * std::sin(phi), std::cos(theta)));
}

}  // namespace sahara
