// glTF materials -> MaterialDesc (Lambertian albedo from the base colour,
// emission, alpha), textures -> TextureDesc with the uv convention of
// scene_desc.h, images decoded through OpenImageIO.
#include <cmath>
#include <numbers>
#include <sstream>

#include "base/error.h"
#include "base/log.h"
#include "io/gltf_detail.h"
#include "io/image_bytes.h"
#include "io/image_io.h"

namespace sahara::gltf {

namespace {

WrapMode wrap_mode(int gl) {
    switch (gl) {
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return WrapMode::clamp;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return WrapMode::mirror;
        default:
            return WrapMode::repeat;
    }
}

double number(const tinygltf::Value& v, const char* key, double fallback) {
    if (!v.Has(key) || !v.Get(key).IsNumber()) return fallback;
    const double d = v.Get(key).GetNumberAsDouble();
    return std::isfinite(d) ? d : fallback;
}

Vec2 pair(const tinygltf::Value& v, const char* key, Vec2 fallback) {
    if (!v.Has(key)) return fallback;
    const tinygltf::Value& a = v.Get(key);
    if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber()) return fallback;
    return {float(a.Get(0).GetNumberAsDouble()), float(a.Get(1).GetNumberAsDouble())};
}

/// KHR_texture_transform maps glTF uvs t = o + R(a) S p, where the spec's GLSL
/// mat3(cos, sin, 0, -sin, cos, 0, ...) is column-major: R(a) = [cos -sin; sin cos].
/// sahara's uvs are F(p) = (u, 1 - v), so the same lookup in sahara space is
/// F(T(F(uv))) = offset' + D R(a) D S uv with D = diag(1, -1), where D R(a) D =
/// [cos sin; -sin cos] is TextureDesc's rotate(a), and
/// offset' = F(o + R(a) S (0, 1)) = (o.x - s.y sin a, 1 - o.y - s.y cos a).
void set_transform(TextureDesc& t, Vec2 offset, float rotation, Vec2 scale) {
    const float s = std::sin(rotation), c = std::cos(rotation);
    t.uv_scale = scale;
    t.uv_rotation = rotation;
    t.uv_offset = {offset.x - scale.y * s, 1.0f - offset.y - scale.y * c};
}

Rgb rgb_of(const std::vector<double>& v, Rgb fallback) {
    if (v.size() < 3) return fallback;
    return Rgb(float(v[0]), float(v[1]), float(v[2]));
}

}  // namespace

Materials::Materials(const Source& src, LoadedModel& out) : src_(src), out_(out) {}

uint32_t Materials::get(int index, const std::string& user) {
    if (index >= 0 && size_t(index) >= src_.model.materials.size())
        throw input_error(src_.file, user, "material " + std::to_string(index) + " does not exist");
    if (auto it = converted_.find(index); it != converted_.end()) return it->second;
    const std::string element = "materials[" + std::to_string(index) + "]";
    out_.materials.push_back(index < 0 ? default_material()
                                       : convert(src_.model.materials[size_t(index)], element));
    return converted_[index] = uint32_t(out_.materials.size() - 1);
}

int Materials::texcoord_set(int index) const {
    if (index < 0 || size_t(index) >= src_.model.materials.size()) return 0;
    const tinygltf::Material& m = src_.model.materials[size_t(index)];
    const tinygltf::TextureInfo& info = m.pbrMetallicRoughness.baseColorTexture.index >= 0
                                            ? m.pbrMetallicRoughness.baseColorTexture
                                            : m.emissiveTexture;
    int set = info.texCoord;
    if (auto it = info.extensions.find("KHR_texture_transform"); it != info.extensions.end())
        set = int(number(it->second, "texCoord", set));
    return set;
}

MaterialDesc Materials::convert(const tinygltf::Material& m, const std::string& element) {
    MaterialDesc out;
    out.name = m.name.empty() ? element : m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    const std::vector<double>& f = pbr.baseColorFactor;
    out.albedo.color = rgb_of(f, Rgb(1.0f));
    const float factor_alpha = f.size() >= 4 ? float(f[3]) : 1.0f;
    int base_tex = -1;
    if (pbr.baseColorTexture.index >= 0) {
        base_tex = texture(pbr.baseColorTexture, true, element + ".pbrMetallicRoughness.baseColorTexture");
        if (base_tex >= 0) {
            out.albedo.kind = ColorSource::Kind::texture;
            out.albedo.texture = base_tex;
        }
    }
    if (m.alphaMode == "MASK" || m.alphaMode == "BLEND") {
        out.alpha = std::clamp(factor_alpha, 0.0f, 1.0f);
        out.alpha_texture = base_tex;
        if (m.alphaMode == "MASK") out.alpha_cutoff = float(m.alphaCutoff);
    }
    float strength = 1.0f;
    if (auto it = m.extensions.find("KHR_materials_emissive_strength"); it != m.extensions.end())
        strength = float(number(it->second, "emissiveStrength", 1.0));
    const Rgb emission = rgb_of(m.emissiveFactor, Rgb(0.0f)) * strength;
    if (max_component(emission) > 0.0f) {
        out.type = MaterialType::emissive;
        out.radiance.color = emission;
        if (m.emissiveTexture.index >= 0) {
            const int t = texture(m.emissiveTexture, true, element + ".emissiveTexture");
            if (t >= 0) {
                out.radiance.kind = ColorSource::Kind::texture;
                out.radiance.texture = t;
            }
        }
    }
    return out;
}

int Materials::texture(const tinygltf::TextureInfo& info, bool srgb, const std::string& element) {
    const tinygltf::Model& m = src_.model;
    if (size_t(info.index) >= m.textures.size())
        throw input_error(src_.file, element, "texture " + std::to_string(info.index) + " does not exist");
    const tinygltf::Texture& tex = m.textures[size_t(info.index)];
    const std::string tex_name = "textures[" + std::to_string(info.index) + "]";
    if (tex.source < 0) {
        log_warning(src_.file + ": " + tex_name +
                    ": no image source (extension-only images are not supported), ignored");
        return -1;
    }
    if (tex.sampler >= 0 && size_t(tex.sampler) >= m.samplers.size())
        throw input_error(src_.file, tex_name, "sampler " + std::to_string(tex.sampler) + " does not exist");
    TextureDesc desc;
    if (tex.sampler >= 0) {
        desc.wrap_u = wrap_mode(m.samplers[size_t(tex.sampler)].wrapS);
        desc.wrap_v = wrap_mode(m.samplers[size_t(tex.sampler)].wrapT);
    }
    Vec2 offset{0, 0}, scale{1, 1};
    float rotation = 0.0f;
    if (auto it = info.extensions.find("KHR_texture_transform"); it != info.extensions.end()) {
        offset = pair(it->second, "offset", offset);
        scale = pair(it->second, "scale", scale);
        rotation = float(number(it->second, "rotation", 0.0));
    }
    set_transform(desc, offset, rotation, scale);
    std::ostringstream key;
    key << tex.source << ' ' << srgb << ' ' << int(desc.wrap_u) << ' ' << int(desc.wrap_v) << ' ' << offset.x
        << ' ' << offset.y << ' ' << scale.x << ' ' << scale.y << ' ' << rotation;
    if (auto it = texture_keys_.find(key.str()); it != texture_keys_.end()) return it->second;
    desc.image = image(tex.source, srgb, tex_name);
    if (!desc.image) return texture_keys_[key.str()] = -1;
    const tinygltf::Image& img = m.images[size_t(tex.source)];
    desc.path = img.uri.empty() ? src_.file + ": images[" + std::to_string(tex.source) + "]" : img.uri;
    out_.textures.push_back(std::move(desc));
    return texture_keys_[key.str()] = int(out_.textures.size()) - 1;
}

std::shared_ptr<const Image> Materials::image(int index, bool srgb, const std::string& user) {
    if (index < 0 || size_t(index) >= src_.model.images.size())
        throw input_error(src_.file, user, "image " + std::to_string(index) + " does not exist");
    if (auto it = images_.find({index, srgb}); it != images_.end()) return it->second;
    const tinygltf::Image& img = src_.model.images[size_t(index)];
    const std::string element = "images[" + std::to_string(index) + "]";
    std::shared_ptr<const Image> result;
    if (auto data = src_.data_uri_images.find(index); data != src_.data_uri_images.end()) {
        result = decode_image_bytes(data->second.data(), data->second.size(), srgb, src_.file, element);
    } else if (img.bufferView >= 0) {
        result = decode_buffer_view_image(img, srgb, element);
    } else {
        const std::filesystem::path path = src_.dir / uri_decode(img.uri);
        std::error_code ec;
        if (img.uri.empty() || !std::filesystem::is_regular_file(path, ec)) {
            log_warning(src_.file + ": " + element + ": image file " + path.string() +
                        " not found, texture ignored");
        } else {
            try {
                result = read_image(path, srgb);
            } catch (const InputError& e) {
                throw input_error(src_.file, element, e.what());
            }
        }
    }
    return images_[{index, srgb}] = result;
}

std::shared_ptr<const Image> Materials::decode_buffer_view_image(const tinygltf::Image& img, bool srgb,
                                                                 const std::string& element) {
    const tinygltf::Model& m = src_.model;
    if (size_t(img.bufferView) >= m.bufferViews.size())
        throw input_error(src_.file, element,
                          "bufferView " + std::to_string(img.bufferView) + " does not exist");
    const tinygltf::BufferView& view = m.bufferViews[size_t(img.bufferView)];
    const std::string view_name = "bufferViews[" + std::to_string(img.bufferView) + "]";
    if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
        throw input_error(src_.file, view_name, "buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& data = m.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
        throw input_error(src_.file, view_name,
                          "extends past the end of buffers[" + std::to_string(view.buffer) + "]");
    return decode_image_bytes(data.data() + view.byteOffset, view.byteLength, srgb, src_.file, element);
}

}  // namespace sahara::gltf
