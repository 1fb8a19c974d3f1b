#pragma once
/// What a ray that leaves the scene sees.
#include <cmath>

#include "math/sampling.h"
#include "scene/scene_desc.h"

namespace sahara {

/// Radiance arriving from direction `dir` (not necessarily unit).
inline Rgb eval_background(const BackgroundDesc& bg, const Vec3& dir) {
    switch (bg.type) {
        case BackgroundDesc::Type::constant: return bg.color;
        case BackgroundDesc::Type::gradient: {
            const float t = 0.5f * (dot(normalize(dir), bg.up) + 1.0f);
            return bg.bottom * (1.0f - t) + bg.top * t;
        }
        case BackgroundDesc::Type::envmap: {
            if (!bg.image) return Rgb(0.0f);
            // Lat-long around `up`: v = 0 at the zenith row (image top).
            const Frame f(normalize(bg.up));
            const Vec3 l = f.to_local(normalize(dir));
            const float phi = std::atan2(l.y, l.x);
            const float theta = std::acos(std::clamp(l.z, -1.0f, 1.0f));
            const Image& img = *bg.image;
            int x = int((phi * (0.5f * kInvPi) + 0.5f) * float(img.width));
            int y = int(theta * kInvPi * float(img.height));
            x = std::clamp(x, 0, img.width - 1);
            y = std::clamp(y, 0, img.height - 1);
            const float* p = &img.rgba[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
            return Rgb(p[0], p[1], p[2]) * bg.strength;
        }
    }
    return Rgb(0.0f);
}

}  // namespace sahara
