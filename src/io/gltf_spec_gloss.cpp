// KHR_materials_pbrSpecularGlossiness (archived, still common in older
// downloads) converted to the metallic-roughness model the renderer has, by
// the conversion Khronos published with the extension: metallic solved from
// the perceived brightness of the diffuse and specular colours, base colour
// blended from both, roughness = 1 - glossiness. The conversion is not linear,
// so textures are converted texel by texel into new base-colour and
// metallic-roughness images at load time.
#include <algorithm>
#include <cmath>

#include "base/log.h"
#include "io/gltf_detail.h"

namespace sahara::gltf {

namespace {

/// The reflectance at normal incidence the metallic-roughness model gives every dielectric.
constexpr float kDielectricF0 = 0.04f;
constexpr float kEpsilon = 1e-6f;

float perceived_brightness(const Rgb& c) {
    return std::sqrt(0.299f * c.x * c.x + 0.587f * c.y * c.y + 0.114f * c.z * c.z);
}

/// The metallic value whose dielectric and metal mix reproduces the brightness of
/// both colours: the positive root of a quadratic in metallic (0 below a dielectric's F0).
float solve_metallic(float diffuse, float specular, float one_minus_specular_strength) {
    if (specular < kDielectricF0) return 0.0f;
    const float a = kDielectricF0;
    const float b =
        diffuse * one_minus_specular_strength / (1.0f - kDielectricF0) + specular - 2.0f * kDielectricF0;
    const float c = kDielectricF0 - specular;
    const float d = std::max(b * b - 4.0f * a * c, 0.0f);
    return std::clamp((-b + std::sqrt(d)) / (2.0f * a), 0.0f, 1.0f);
}

struct MetalRough {
    Rgb base;
    float metallic = 0, roughness = 1;
};

MetalRough to_metal_rough(const Rgb& diffuse, const Rgb& specular, float glossiness) {
    const float one_minus_strength = 1.0f - max_component(specular);
    MetalRough out;
    out.metallic =
        solve_metallic(perceived_brightness(diffuse), perceived_brightness(specular), one_minus_strength);
    const float m = out.metallic;
    const Rgb from_diffuse =
        diffuse * (one_minus_strength / (1.0f - kDielectricF0) / std::max(1.0f - m, kEpsilon));
    const Rgb from_specular = (specular - Rgb(kDielectricF0 * (1.0f - m))) * (1.0f / std::max(m, kEpsilon));
    const Rgb base = from_diffuse * (1.0f - m * m) + from_specular * (m * m);
    out.base =
        Rgb(std::clamp(base.x, 0.0f, 1.0f), std::clamp(base.y, 0.0f, 1.0f), std::clamp(base.z, 0.0f, 1.0f));
    out.roughness = std::clamp(1.0f - glossiness, 0.0f, 1.0f);
    return out;
}

/// RGBA of `img` at (u, v) in [0, 1]^2 (v down, as the rows), bilinear, clamped at the edges.
void lookup(const Image& img, float u, float v, float rgba[4]) {
    const float x = std::clamp(u * float(img.width) - 0.5f, 0.0f, float(img.width - 1));
    const float y = std::clamp(v * float(img.height) - 0.5f, 0.0f, float(img.height - 1));
    const int x0 = int(x), y0 = int(y);
    const int x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
    const float fx = x - float(x0), fy = y - float(y0);
    auto at = [&](int px, int py, int c) {
        return img.rgba[(size_t(py) * size_t(img.width) + size_t(px)) * 4 + size_t(c)];
    };
    for (int c = 0; c < 4; ++c)
        rgba[c] = (at(x0, y0, c) * (1 - fx) + at(x1, y0, c) * fx) * (1 - fy) +
                  (at(x0, y1, c) * (1 - fx) + at(x1, y1, c) * fx) * fy;
}

/// The mean RGBA of an image.
void mean_rgba(const Image& img, float rgba[4]) {
    double sum[4] = {0, 0, 0, 0};
    const size_t n = size_t(img.width) * size_t(img.height);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c) sum[c] += double(img.rgba[4 * i + size_t(c)]);
    for (int c = 0; c < 4; ++c) rgba[c] = n ? float(sum[c] / double(n)) : 1.0f;
}

/// The extension's factors, and its textures as far as they could be read.
struct SpecGloss {
    float diffuse[4] = {1, 1, 1, 1};
    Rgb specular{1.0f};
    float glossiness = 1;
    std::optional<TextureDesc> diffuse_tex, spec_gloss_tex;
};

bool same_mapping(const TextureDesc& a, const TextureDesc& b) {
    return a.wrap_u == b.wrap_u && a.wrap_v == b.wrap_v && a.uv_offset.x == b.uv_offset.x &&
           a.uv_offset.y == b.uv_offset.y && a.uv_scale.x == b.uv_scale.x && a.uv_scale.y == b.uv_scale.y &&
           a.uv_rotation == b.uv_rotation && a.texcoord == b.texcoord;
}

/// Converts every texel of the larger texture's grid; `spec_mean` set: the
/// specular-glossiness texture is mapped differently and stands in by its mean.
void bake(const SpecGloss& sg, const TextureDesc& grid, bool spec_mean, Image& base, Image& mr) {
    base.width = mr.width = grid.image->width;
    base.height = mr.height = grid.image->height;
    base.rgba.resize(size_t(base.width) * size_t(base.height) * 4);
    mr.rgba.resize(base.rgba.size());
    float sg_mean[4] = {1, 1, 1, 1};
    if (spec_mean && sg.spec_gloss_tex) mean_rgba(*sg.spec_gloss_tex->image, sg_mean);
    for (int y = 0; y < base.height; ++y)
        for (int x = 0; x < base.width; ++x) {
            const float u = (float(x) + 0.5f) / float(base.width), v = (float(y) + 0.5f) / float(base.height);
            float d[4] = {1, 1, 1, 1}, s[4] = {sg_mean[0], sg_mean[1], sg_mean[2], sg_mean[3]};
            if (sg.diffuse_tex) lookup(*sg.diffuse_tex->image, u, v, d);
            if (sg.spec_gloss_tex && !spec_mean) lookup(*sg.spec_gloss_tex->image, u, v, s);
            const MetalRough c =
                to_metal_rough(Rgb(d[0] * sg.diffuse[0], d[1] * sg.diffuse[1], d[2] * sg.diffuse[2]),
                               sg.specular * Rgb(s[0], s[1], s[2]), sg.glossiness * s[3]);
            const size_t at = (size_t(y) * size_t(base.width) + size_t(x)) * 4;
            const float base_texel[4] = {c.base.x, c.base.y, c.base.z, d[3] * sg.diffuse[3]};
            const float mr_texel[4] = {1.0f, c.roughness, c.metallic, 1.0f};  // glTF: G roughness, B metallic
            std::copy(base_texel, base_texel + 4, &base.rgba[at]);
            std::copy(mr_texel, mr_texel + 4, &mr.rgba[at]);
        }
}

double factor(const tinygltf::Value& v, const char* key, int i, double fallback) {
    if (!v.Has(key) || !v.Get(key).IsArray() || int(v.Get(key).ArrayLen()) <= i) return fallback;
    const tinygltf::Value& x = v.Get(key).Get(i);
    const double d = x.IsNumber() ? x.GetNumberAsDouble() : fallback;
    return std::isfinite(d) ? d : fallback;
}

}  // namespace

void Materials::convert_spec_gloss(MaterialDesc& out, const tinygltf::Material& m, const tinygltf::Value& ext,
                                   const std::string& element) {
    const std::string where = element + ".extensions.KHR_materials_pbrSpecularGlossiness";
    SpecGloss sg;
    for (int i = 0; i < 4; ++i)
        sg.diffuse[i] = std::clamp(float(factor(ext, "diffuseFactor", i, 1.0)), 0.0f, 1.0f);
    for (int i = 0; i < 3; ++i)
        sg.specular[i] = std::clamp(float(factor(ext, "specularFactor", i, 1.0)), 0.0f, 1.0f);
    if (ext.Has("glossinessFactor") && ext.Get("glossinessFactor").IsNumber())
        sg.glossiness = std::clamp(float(ext.Get("glossinessFactor").GetNumberAsDouble()), 0.0f, 1.0f);
    std::string key;
    if (auto ref = texture_info(ext, "diffuseTexture"))
        sg.diffuse_tex = texture_desc(*ref, true, where + ".diffuseTexture", &key);
    // RGB is an sRGB-encoded colour, A linear glossiness (the decoder keeps alpha linear).
    if (auto ref = texture_info(ext, "specularGlossinessTexture"))
        sg.spec_gloss_tex = texture_desc(*ref, true, where + ".specularGlossinessTexture", &key);
    if (sg.diffuse_tex && !sg.diffuse_tex->image) sg.diffuse_tex.reset();
    if (sg.spec_gloss_tex && !sg.spec_gloss_tex->image) sg.spec_gloss_tex.reset();
    out.extensions.push_back("KHR_materials_pbrSpecularGlossiness");
    if (!sg.diffuse_tex && !sg.spec_gloss_tex) {
        const MetalRough c =
            to_metal_rough(Rgb(sg.diffuse[0], sg.diffuse[1], sg.diffuse[2]), sg.specular, sg.glossiness);
        out.albedo.color = c.base;
        out.metallic = c.metallic;
        out.roughness = c.roughness;
        set_alpha(out, m, sg.diffuse[3], -1, element);
        return;
    }
    // Bake on the grid and mapping of the larger texture.
    const bool both = sg.diffuse_tex && sg.spec_gloss_tex;
    const TextureDesc* grid = sg.diffuse_tex ? &*sg.diffuse_tex : &*sg.spec_gloss_tex;
    if (both && size_t(sg.spec_gloss_tex->image->width) * size_t(sg.spec_gloss_tex->image->height) >
                    size_t(grid->image->width) * size_t(grid->image->height))
        grid = &*sg.spec_gloss_tex;
    const bool spec_mean = both && !same_mapping(*sg.diffuse_tex, *sg.spec_gloss_tex);
    if (spec_mean) {
        grid = &*sg.diffuse_tex;
        log_warning(src_.file + ": " + where +
                    ": the two textures are mapped differently; the specular-glossiness texture is "
                    "reduced to its mean");
    }
    auto base = std::make_shared<Image>(), mr = std::make_shared<Image>();
    bake(sg, *grid, spec_mean, *base, *mr);
    TextureDesc base_tex = *grid, mr_tex = *grid;
    base_tex.image = base;
    base_tex.path = grid->path + " (converted from specular-glossiness)";
    mr_tex.image = mr;
    mr_tex.path = base_tex.path;
    out_.textures.push_back(std::move(base_tex));
    out.albedo.kind = ColorSource::Kind::texture;
    out.albedo.color = Rgb(1.0f);
    out.albedo.texture = int(out_.textures.size()) - 1;
    out_.textures.push_back(std::move(mr_tex));
    out.metallic_roughness_texture = int(out_.textures.size()) - 1;
    out.metallic = out.roughness = 1.0f;
    set_alpha(out, m, 1.0f, out.albedo.texture, element);  // the factor's alpha is in the baked texture
}

}  // namespace sahara::gltf
