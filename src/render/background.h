#pragma once
/// What a ray that leaves the scene sees.
#include <algorithm>
#include <cmath>

#include "math/sampling.h"
#include "desc/scene_desc.h"

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

/// Envmap radiance at lat-long coordinates (nearest pixel, times strength).
inline Rgb envmap_radiance(const BackgroundDesc& bg, Vec2 uv) {
    const Image& img = *bg.image;
    const int x = std::clamp(int(uv.x * float(img.width)), 0, img.width - 1);
    const int y = std::clamp(int(uv.y * float(img.height)), 0, img.height - 1);
    const float* p = &img.rgba[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
    return Rgb(p[0], p[1], p[2]) * bg.strength;
}

/// Radiance arriving from direction `dir` (not necessarily unit).
inline Rgb eval_background(const BackgroundDesc& bg, const Vec3& dir) {
    switch (bg.type) {
        case BackgroundDesc::Type::constant:
            return bg.color;
        case BackgroundDesc::Type::gradient: {
            const float t = 0.5f * (dot(normalize(dir), bg.up) + 1.0f);
            return bg.bottom * (1.0f - t) + bg.top * t;
        }
        case BackgroundDesc::Type::envmap:
            if (!bg.image) return Rgb(0.0f);
            return envmap_radiance(bg, envmap_uv(bg.up, dir));
    }
    return Rgb(0.0f);
}

}  // namespace sahara
