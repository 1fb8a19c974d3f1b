#include "render/tonemap.h"

#include <algorithm>
#include <cmath>

namespace sahara {

float tonemap_value(float v, Tonemap curve) {
    v = std::max(v, 0.0f);
    switch (curve) {
        case Tonemap::clamp: return std::min(v, 1.0f);
        case Tonemap::reinhard: return v / (1.0f + v);
        case Tonemap::aces: {
            // Narkowicz's 2015 fit of the ACES reference rendering transform.
            const float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
            return std::clamp((v * (a * v + b)) / (v * (c * v + d) + e), 0.0f, 1.0f);
        }
    }
    return std::min(v, 1.0f);
}

std::vector<float> tonemap_image(const std::vector<float>& rgb, float exposure_stops, Tonemap curve, size_t* clipped) {
    const float scale = std::exp2(exposure_stops);
    std::vector<float> out(rgb.size());
    size_t n_clipped = 0;
    for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
        bool clip = false;
        for (size_t c = 0; c < 3; ++c) {
            const float v = rgb[i + c] * scale;
            clip |= curve == Tonemap::clamp && v > 1.0f;
            out[i + c] = tonemap_value(v, curve);
        }
        n_clipped += clip;
    }
    if (clipped) *clipped = n_clipped;
    return out;
}

}  // namespace sahara
