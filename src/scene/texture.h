#pragma once
/// Evaluating colour sources: constants, world-space 3-D checkers, and image
/// textures (bilinear, wrap modes, KHR_texture_transform). UV convention: v = 0
/// at the bottom row of the image.
#include <vector>

#include "desc/scene_desc.h"

namespace sahara {

/// RGBA of a texture at uv (bilinear, wrap modes and uv transform applied).
TVec3<float> sample_texture_rgb(const TextureDesc& tex, Vec2 uv, float* alpha = nullptr);

/// The colour a source gives at world point p with surface uv.
inline Rgb eval_color(const ColorSource& src, const std::vector<TextureDesc>& textures, const Vec3& p,
                      Vec2 uv) {
    switch (src.kind) {
        case ColorSource::Kind::constant:
            return src.color;
        case ColorSource::Kind::checker: {
            const float inv = 1.0f / src.checker_scale;
            const Vec3 q = p + src.checker_offset;
            const long sum =
                long(std::floor(q.x * inv)) + long(std::floor(q.y * inv)) + long(std::floor(q.z * inv));
            return (sum & 1) ? src.odd : src.even;
        }
        case ColorSource::Kind::texture:
            return src.color * sample_texture_rgb(textures[size_t(src.texture)], uv);
    }
    return src.color;
}

}  // namespace sahara
