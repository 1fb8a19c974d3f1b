#include "scene/texture.h"

#include <algorithm>
#include <cmath>

namespace sahara {

namespace {

int wrap_index(int i, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::clamp:
            return std::clamp(i, 0, n - 1);
        case WrapMode::mirror: {
            int period = 2 * n;
            int m = ((i % period) + period) % period;
            return m < n ? m : period - 1 - m;
        }
        case WrapMode::repeat:
            break;
    }
    return ((i % n) + n) % n;
}

}  // namespace

TVec3<float> sample_texture_rgb(const TextureDesc& tex, Vec2 uv, float* alpha) {
    const Image& img = *tex.image;
    // KHR_texture_transform: scale, then rotate, then offset.
    float su = uv.x * tex.uv_scale.x, sv = uv.y * tex.uv_scale.y;
    if (tex.uv_rotation != 0.0f) {
        float c = std::cos(tex.uv_rotation), s = std::sin(tex.uv_rotation);
        float ru = c * su + s * sv, rv = -s * su + c * sv;
        su = ru;
        sv = rv;
    }
    su += tex.uv_offset.x;
    sv += tex.uv_offset.y;
    // Pixel centres at half-integers; v = 0 is the bottom row.
    const float fx = su * float(img.width) - 0.5f;
    const float fy = (1.0f - sv) * float(img.height) - 0.5f;
    if (!std::isfinite(fx) || !std::isfinite(fy)) return Vec3(0.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float tx = fx - x0f, ty = fy - y0f;
    const int x0 = int(std::clamp(x0f, -1e8f, 1e8f)), y0 = int(std::clamp(y0f, -1e8f, 1e8f));
    float acc[4] = {0, 0, 0, 0};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const int xi = wrap_index(x0 + i, img.width, tex.wrap_u);
            const int yi = wrap_index(y0 + j, img.height, tex.wrap_v);
            const float w = (i ? tx : 1.0f - tx) * (j ? ty : 1.0f - ty);
            const float* px = &img.rgba[(size_t(yi) * size_t(img.width) + size_t(xi)) * 4];
            for (int c = 0; c < 4; ++c) acc[c] += w * px[c];
        }
    if (alpha) *alpha = acc[3];
    return {acc[0], acc[1], acc[2]};
}

}  // namespace sahara
