#pragma once
/// What a ray that leaves the scene sees.
#include <algorithm>
#include <cmath>

#include "math/latlong.h"
#include "desc/scene_desc.h"

namespace sahara {

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
