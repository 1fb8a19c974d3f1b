// glTF materials -> MaterialDesc of type pbr (every core input and the
// transmission, ior, volume, emissive-strength, clearcoat, sheen, anisotropy, iridescence, dispersion
// and diffuse-transmission extensions),
// textures -> TextureDesc with the uv convention of scene_desc.h, images decoded through OpenImageIO.
// Occlusion maps are ignored on purpose: a path tracer computes occlusion.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
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

/// KHR_texture_transform maps glTF uvs t = o + R S p. The spec's GLSL and its
/// worked example disagree about R; the example ("offset [0, 1], rotation pi/2,
/// scale 0.5 uses the lower left quadrant rotated clockwise"), the Khronos sample
/// viewer, three.js and the TextureTransformTest model all use R(a) = [cos sin; -sin cos].
/// sahara's uvs are F(p) = (u, 1 - v), so the same lookup in sahara space is
/// F(T(F(uv))) = offset' + D R(a) D S uv with D = diag(1, -1), where D R(a) D =
/// [cos -sin; sin cos] is TextureDesc's rotate(-a), and
/// offset' = F(o + R(a) S (0, 1)) = (o.x + s.y sin a, 1 - o.y - s.y cos a).
void set_transform(TextureDesc& t, Vec2 offset, float rotation, Vec2 scale) {
    const float s = std::sin(rotation), c = std::cos(rotation);
    t.uv_scale = scale;
    t.uv_rotation = -rotation;
    t.uv_offset = {offset.x + scale.y * s, 1.0f - offset.y - scale.y * c};
}

std::vector<double> numbers(const tinygltf::Value& v, const char* key) {
    std::vector<double> out;
    if (!v.Has(key) || !v.Get(key).IsArray()) return out;
    const tinygltf::Value& a = v.Get(key);
    for (size_t i = 0; i < a.ArrayLen(); ++i)
        if (a.Get(int(i)).IsNumber()) out.push_back(a.Get(int(i)).GetNumberAsDouble());
    return out;
}

const tinygltf::Value* transform_of(const tinygltf::ExtensionMap& extensions) {
    auto it = extensions.find("KHR_texture_transform");
    return it == extensions.end() ? nullptr : &it->second;
}

Rgb rgb_of(const std::vector<double>& v, Rgb fallback) {
    if (v.size() < 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return fallback;
    return Rgb(float(v[0]), float(v[1]), float(v[2]));
}

/// Material extensions that convert() reads before set_extensions runs.
bool read_elsewhere(const std::string& name) {
    return name == "KHR_materials_emissive_strength" || name == "KHR_materials_pbrSpecularGlossiness" ||
           name == "KHR_materials_specular";
}

TextureRef texture_ref(const tinygltf::TextureInfo& info) {
    return {info.index, info.texCoord, transform_of(info.extensions)};
}

}  // namespace

Materials::Materials(const Source& src, LoadedModel& out) : src_(src), out_(out) {}

uint32_t Materials::get(int index, const std::string& user, bool vertex_colors) {
    if (index >= 0 && size_t(index) >= src_.model.materials.size())
        throw input_error(src_.file, user, "material " + std::to_string(index) + " does not exist");
    // Without a material, a primitive with COLOR_0 gets glTF's default material so
    // that its colours show; without colours it keeps sahara's default grey.
    const int key = index < 0 && vertex_colors ? -2 : index;
    auto it = converted_.find(key);
    if (it == converted_.end()) {
        const std::string element = "materials[" + std::to_string(index) + "]";
        MaterialDesc m = key == -1   ? default_material()
                         : key == -2 ? convert(tinygltf::Material{}, "default (vertex colours)")
                                     : convert(src_.model.materials[size_t(index)], element);
        out_.materials.push_back(std::move(m));
        it = converted_.emplace(key, uint32_t(out_.materials.size() - 1)).first;
    }
    if (vertex_colors) out_.materials[it->second].vertex_colors = true;
    return it->second;
}

MaterialDesc Materials::convert(const tinygltf::Material& m, const std::string& element) {
    MaterialDesc out;
    out.name = m.name.empty() ? element : m.name;
    out.type = MaterialType::pbr;
    out.double_sided = m.doubleSided;
    if (m.extensions.count("KHR_materials_unlit")) return convert_unlit(m, element, std::move(out));
    if (auto sg = m.extensions.find("KHR_materials_pbrSpecularGlossiness"); sg != m.extensions.end()) {
        convert_spec_gloss(out, m, sg->second, element);  // replaces pbrMetallicRoughness, as its spec says
    } else {
        const auto& pbr = m.pbrMetallicRoughness;
        set_base_color(out, m, element);
        out.metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
        out.roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
        if (pbr.metallicRoughnessTexture.index >= 0)
            out.metallic_roughness_texture =
                texture(pbr.metallicRoughnessTexture, false,
                        element + ".pbrMetallicRoughness.metallicRoughnessTexture");
    }
    if (auto sp = m.extensions.find("KHR_materials_specular"); sp != m.extensions.end())
        set_specular(out, sp->second, element + ".extensions.KHR_materials_specular");
    if (m.normalTexture.index >= 0) {
        const TextureRef ref{m.normalTexture.index, m.normalTexture.texCoord,
                             transform_of(m.normalTexture.extensions)};
        out.normal_texture = texture(ref, false, element + ".normalTexture");
        out.normal_scale = float(m.normalTexture.scale);
    }
    if (m.occlusionTexture.index >= 0) out.ignored.push_back("occlusion map");
    set_emission(out, m, element);
    set_extensions(out, m, element);
    note_webp(out);
    return out;
}

/// baseColorFactor x baseColorTexture, and alpha from both.
void Materials::set_base_color(MaterialDesc& out, const tinygltf::Material& m, const std::string& element) {
    const auto& pbr = m.pbrMetallicRoughness;
    const std::vector<double>& f = pbr.baseColorFactor;
    out.albedo.color = rgb_of(f, Rgb(1.0f));
    int base_tex = -1;
    if (pbr.baseColorTexture.index >= 0) {
        base_tex = texture(pbr.baseColorTexture, true, element + ".pbrMetallicRoughness.baseColorTexture");
        if (base_tex >= 0) {
            out.albedo.kind = ColorSource::Kind::texture;
            out.albedo.texture = base_tex;
        }
    }
    set_alpha(out, m, f.size() >= 4 ? float(f[3]) : 1.0f, base_tex, element);
}

/// KHR_materials_unlit: the base colour (and alpha) only; every other input of
/// the material is a fallback for viewers without the extension, so none is read.
MaterialDesc Materials::convert_unlit(const tinygltf::Material& m, const std::string& element,
                                      MaterialDesc out) {
    out.type = MaterialType::unlit;
    set_base_color(out, m, element);
    out.extensions.push_back("KHR_materials_unlit");
    note_webp(out);
    return out;
}

/// glTF alphaMode: OPAQUE ignores alpha entirely; MASK cuts at alphaCutoff;
/// BLEND is rendered as stochastic transparency.
void Materials::set_alpha(MaterialDesc& out, const tinygltf::Material& m, float factor_alpha, int base_tex,
                          const std::string& element) {
    if (m.alphaMode == "OPAQUE" || m.alphaMode.empty()) return;
    if (m.alphaMode != "MASK" && m.alphaMode != "BLEND")
        throw input_error(src_.file, element + ".alphaMode", "unknown mode '" + m.alphaMode + "'");
    out.alpha = std::clamp(factor_alpha, 0.0f, 1.0f);
    out.alpha_texture = base_tex;
    if (m.alphaMode == "MASK") out.alpha_cutoff = float(m.alphaCutoff);
}

/// emissiveFactor x emissiveTexture x KHR_materials_emissive_strength, added to
/// what the surface reflects.
void Materials::set_emission(MaterialDesc& out, const tinygltf::Material& m, const std::string& element) {
    float strength = 1.0f;
    if (auto it = m.extensions.find("KHR_materials_emissive_strength"); it != m.extensions.end())
        strength = float(number(it->second, "emissiveStrength", 1.0));
    if (strength < 0.0f) {  // the extension's schema has minimum 0; a light cannot absorb
        log_warning(src_.file + ": " + element + ": KHR_materials_emissive_strength: emissiveStrength " +
                    std::to_string(strength) + " is negative, using 0");
        strength = 0.0f;
    }
    const Rgb emission = rgb_of(m.emissiveFactor, Rgb(0.0f)) * strength;
    if (!(max_component(emission) > 0.0f)) return;  // a texture times a zero factor emits nothing
    out.radiance.color = emission;
    if (m.emissiveTexture.index >= 0) {
        const int t = texture(m.emissiveTexture, true, element + ".emissiveTexture");
        if (t >= 0) {
            out.radiance.kind = ColorSource::Kind::texture;
            out.radiance.texture = t;
        }
    }
}

/// KHR_materials_transmission, _ior and _volume; other material extensions
/// are named once per file as ignored.
void Materials::set_extensions(MaterialDesc& out, const tinygltf::Material& m, const std::string& element) {
    // Without KHR_materials_volume (or with thicknessFactor 0) a transmissive
    // surface is thin-walled: light passes through it without refraction.
    out.thin_walled = true;
    for (const auto& [name, value] : m.extensions) {
        const std::string ext = element + ".extensions." + name;
        if (name == "KHR_materials_transmission") {
            out.transmission = std::clamp(float(number(value, "transmissionFactor", 0.0)), 0.0f, 1.0f);
            if (auto info = texture_info(value, "transmissionTexture"))
                out.transmission_texture = texture(*info, false, ext + ".transmissionTexture");
        } else if (name == "KHR_materials_ior") {
            const float ior = float(number(value, "ior", 1.5));
            if (ior >= 1.0f)
                out.ior = ior;
            else
                log_warning(src_.file + ": " + ext + ": ior " + std::to_string(ior) +
                            " is below 1, 1.5 used");
        } else if (name == "KHR_materials_volume") {
            out.thin_walled = !(number(value, "thicknessFactor", 0.0) > 0.0);
            const float distance = float(number(value, "attenuationDistance", kInfinity));
            if (distance > 0.0f) out.attenuation_distance = distance;
            out.attenuation_color = rgb_of(numbers(value, "attenuationColor"), Rgb(1.0f));
        } else if (name == "KHR_materials_clearcoat") {
            set_clearcoat(out.layers, value, ext);
            out.extensions.push_back(name);
        } else if (name == "KHR_materials_sheen") {
            set_sheen(out.layers, value, ext);
            out.extensions.push_back(name);
        } else if (name == "KHR_materials_anisotropy") {
            set_anisotropy(out, value, ext);
            out.extensions.push_back(name);
        } else if (name == "KHR_materials_iridescence") {
            set_iridescence(out, value, ext);
            out.extensions.push_back(name);
        } else if (name == "KHR_materials_dispersion") {
            set_dispersion(out, value, ext);
            out.extensions.push_back(name);
        } else if (name == "KHR_materials_diffuse_transmission") {
            set_diffuse_transmission(out, value, ext);
            out.extensions.push_back(name);
        } else if (!read_elsewhere(name)) {
            out.ignored.push_back(name);
            if (ignored_.insert(name).second)
                log_warning(src_.file + ": " + ext + ": extension not supported, ignored");
        }
    }
}

/// KHR_materials_specular: the strength (texture A) and colour (texture RGB,
/// sRGB) of the dielectric layer's reflection. The colour factor may exceed 1
/// (F0 is clamped to 1 where it is used).
void Materials::set_specular(MaterialDesc& out, const tinygltf::Value& ext, const std::string& where) {
    out.specular = std::clamp(float(number(ext, "specularFactor", 1.0)), 0.0f, 1.0f);
    if (auto info = texture_info(ext, "specularTexture"))
        out.specular_texture = texture(*info, false, where + ".specularTexture");
    const Rgb color = rgb_of(numbers(ext, "specularColorFactor"), Rgb(1.0f));
    out.specular_color = Rgb(std::max(color.x, 0.0f), std::max(color.y, 0.0f), std::max(color.z, 0.0f));
    if (auto info = texture_info(ext, "specularColorTexture"))
        out.specular_color_texture = texture(*info, true, where + ".specularColorTexture");
    out.extensions.push_back("KHR_materials_specular");
}

/// KHR_materials_clearcoat: the coat's weight (texture R), roughness (texture G)
/// and its own normal map. Data textures, read linear.
void Materials::set_clearcoat(PbrLayersDesc& out, const tinygltf::Value& ext, const std::string& element) {
    out.clearcoat = std::clamp(float(number(ext, "clearcoatFactor", 0.0)), 0.0f, 1.0f);
    if (auto info = texture_info(ext, "clearcoatTexture"))
        out.clearcoat_texture = texture(*info, false, element + ".clearcoatTexture");
    out.clearcoat_roughness = std::clamp(float(number(ext, "clearcoatRoughnessFactor", 0.0)), 0.0f, 1.0f);
    if (auto info = texture_info(ext, "clearcoatRoughnessTexture"))
        out.clearcoat_roughness_texture = texture(*info, false, element + ".clearcoatRoughnessTexture");
    if (auto info = texture_info(ext, "clearcoatNormalTexture")) {
        out.clearcoat_normal_texture = texture(*info, false, element + ".clearcoatNormalTexture");
        out.clearcoat_normal_scale = float(number(ext.Get("clearcoatNormalTexture"), "scale", 1.0));
    }
}

/// KHR_materials_sheen: the sheen colour (texture RGB, sRGB-encoded like every
/// colour) and roughness (texture A, linear).
void Materials::set_sheen(PbrLayersDesc& out, const tinygltf::Value& ext, const std::string& element) {
    const Rgb color = rgb_of(numbers(ext, "sheenColorFactor"), Rgb(0.0f));
    out.sheen_color = Rgb(std::clamp(color.x, 0.0f, 1.0f), std::clamp(color.y, 0.0f, 1.0f),
                          std::clamp(color.z, 0.0f, 1.0f));
    if (auto info = texture_info(ext, "sheenColorTexture"))
        out.sheen_color_texture = texture(*info, true, element + ".sheenColorTexture");
    out.sheen_roughness = std::clamp(float(number(ext, "sheenRoughnessFactor", 0.0)), 0.0f, 1.0f);
    if (auto info = texture_info(ext, "sheenRoughnessTexture"))
        out.sheen_roughness_texture = texture(*info, false, element + ".sheenRoughnessTexture");
}

/// KHR_materials_anisotropy: strength (factor x texture B), rotation (radians)
/// and direction (texture RG). The direction texture is data: read linear.
/// A strength outside [0, 1] is clamped with a warning; a value that is not a
/// number is refused.
void Materials::set_anisotropy(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element) {
    for (const char* key : {"anisotropyStrength", "anisotropyRotation"})
        if (ext.Has(key) && !ext.Get(key).IsNumber())
            throw input_error(src_.file, element + "." + key, "must be a number");
    const float strength = float(number(ext, "anisotropyStrength", 0.0));
    out.anisotropy = std::clamp(strength, 0.0f, 1.0f);
    if (out.anisotropy != strength)
        log_warning(src_.file + ": " + element + ".anisotropyStrength: " + std::to_string(strength) +
                    " is outside [0, 1], " + std::to_string(out.anisotropy) + " used");
    out.anisotropy_rotation = float(number(ext, "anisotropyRotation", 0.0));
    if (auto info = texture_info(ext, "anisotropyTexture"))
        out.anisotropy_texture = texture(*info, false, element + ".anisotropyTexture");
}

/// KHR_materials_iridescence: the film's weight (factor x texture R), ior and
/// thickness (nm; texture G between the minimum and the maximum). Data
/// textures, read linear. A value that is not a number or outside the
/// extension's schema (weight in [0, 1], ior >= 1, thicknesses >= 0) is refused.
void Materials::set_iridescence(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element) {
    IridescenceDesc& d = out.iridescence;
    d.factor = bounded_number(ext, "iridescenceFactor", 0.0, 0.0, 1.0, element);
    d.ior = bounded_number(ext, "iridescenceIor", 1.3, 1.0, -1, element);
    d.thickness_min = bounded_number(ext, "iridescenceThicknessMinimum", 100.0, 0.0, -1, element);
    d.thickness_max = bounded_number(ext, "iridescenceThicknessMaximum", 400.0, 0.0, -1, element);
    if (auto info = texture_info(ext, "iridescenceTexture"))
        d.texture = texture(*info, false, element + ".iridescenceTexture");
    if (auto info = texture_info(ext, "iridescenceThicknessTexture"))
        d.thickness_texture = texture(*info, false, element + ".iridescenceThicknessTexture");
}

/// KHR_materials_dispersion: 20 / the Abbe number of the volume's ior (>= 0).
void Materials::set_dispersion(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element) {
    out.dispersion = bounded_number(ext, "dispersion", 0.0, 0.0, -1, element);
}

/// KHR_materials_diffuse_transmission: the share of the diffuse base that
/// transmits (factor x texture A, linear) and its colour (factor x texture RGB,
/// sRGB), each factor within the extension's schema.
void Materials::set_diffuse_transmission(MaterialDesc& out, const tinygltf::Value& ext,
                                         const std::string& element) {
    out.diffuse_transmission = bounded_number(ext, "diffuseTransmissionFactor", 0.0, 0.0, 1.0, element);
    if (auto info = texture_info(ext, "diffuseTransmissionTexture"))
        out.diffuse_transmission_texture = texture(*info, false, element + ".diffuseTransmissionTexture");
    const char* color_key = "diffuseTransmissionColorFactor";
    if (ext.Has(color_key)) {
        const std::vector<double> c = numbers(ext, color_key);
        const tinygltf::Value& v = ext.Get(color_key);
        const bool valid = v.IsArray() && v.ArrayLen() == 3 && c.size() == 3 &&
                           std::all_of(c.begin(), c.end(), [](double x) { return x >= 0.0 && x <= 1.0; });
        if (!valid) throw input_error(src_.file, element + "." + color_key, "must be 3 numbers in [0, 1]");
        out.diffuse_transmission_color = rgb_of(c, Rgb(1.0f));
    }
    if (auto info = texture_info(ext, "diffuseTransmissionColorTexture"))
        out.diffuse_transmission_color_texture =
            texture(*info, true, element + ".diffuseTransmissionColorTexture");
}

/// The number at `key` of an extension object, `fallback` without one; a value
/// that is not a number or lies outside [low, high] (high < 0: no upper limit)
/// is refused, naming the element.
float Materials::bounded_number(const tinygltf::Value& ext, const char* key, double fallback, double low,
                                double high, const std::string& element) const {
    if (!ext.Has(key)) return float(fallback);
    const tinygltf::Value& v = ext.Get(key);
    const double d = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
    if (!(d >= low && (high < 0 || d <= high) && d < 1e30)) {
        std::ostringstream range;
        range << "must be a number ";
        if (high < 0)
            range << ">= " << low;
        else
            range << "in [" << low << ", " << high << "]";
        throw input_error(src_.file, element + "." + key, range.str());
    }
    return float(d);
}

/// A textureInfo inside an extension object (tinygltf leaves those as JSON values).
std::optional<TextureRef> Materials::texture_info(const tinygltf::Value& ext, const char* key) const {
    if (!ext.Has(key) || !ext.Get(key).IsObject()) return std::nullopt;
    const tinygltf::Value& v = ext.Get(key);
    TextureRef ref{int(number(v, "index", -1)), int(number(v, "texCoord", 0)), nullptr};
    if (v.Has("extensions") && v.Get("extensions").Has("KHR_texture_transform"))
        ref.transform = &v.Get("extensions").Get("KHR_texture_transform");
    return ref;
}

int Materials::texture(const tinygltf::TextureInfo& info, bool srgb, const std::string& element) {
    return texture(texture_ref(info), srgb, element);
}

int Materials::texture(const TextureRef& ref, bool srgb, const std::string& element) {
    std::string key;
    bool webp = false;
    std::optional<TextureDesc> desc = texture_desc(ref, srgb, element, &key, &webp);
    if (!desc) return -1;
    if (auto it = texture_keys_.find(key); it != texture_keys_.end()) return it->second;
    if (!desc->image) return texture_keys_[key] = -1;
    out_.textures.push_back(std::move(*desc));
    if (webp) webp_textures_.insert(int(out_.textures.size()) - 1);
    return texture_keys_[key] = int(out_.textures.size()) - 1;
}

void Materials::note_webp(MaterialDesc& out) const {
    if (webp_textures_.empty()) return;
    for (int t :
         {out.albedo.texture, out.radiance.texture, out.metallic_roughness_texture, out.normal_texture,
          out.transmission_texture, out.specular_texture, out.specular_color_texture})
        if (webp_textures_.count(t)) {
            out.extensions.push_back("EXT_texture_webp");
            return;
        }
}

std::optional<TextureDesc> Materials::texture_desc(const TextureRef& ref, bool srgb,
                                                   const std::string& element, std::string* cache_key,
                                                   bool* from_webp) {
    const tinygltf::Model& m = src_.model;
    if (ref.index < 0 || size_t(ref.index) >= m.textures.size())
        throw input_error(src_.file, element, "texture " + std::to_string(ref.index) + " does not exist");
    const tinygltf::Texture& tex = m.textures[size_t(ref.index)];
    const std::string tex_name = "textures[" + std::to_string(ref.index) + "]";
    const int webp = webp_source(tex);
    if (tex.source < 0 && webp < 0) {
        log_warning(src_.file + ": " + tex_name + ": no image source sahara reads, ignored");
        return std::nullopt;
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
    desc.texcoord = ref.texcoord;
    if (ref.transform) {
        offset = pair(*ref.transform, "offset", offset);
        scale = pair(*ref.transform, "scale", scale);
        rotation = float(number(*ref.transform, "rotation", 0.0));
        desc.texcoord = int(number(*ref.transform, "texCoord", desc.texcoord));
    }
    if (desc.texcoord != 0 && desc.texcoord != 1) {
        log_warning(src_.file + ": " + element + ": TEXCOORD_" + std::to_string(desc.texcoord) +
                    " is not supported (sets 0 and 1 are), set 0 used");
        desc.texcoord = 0;
    }
    set_transform(desc, offset, rotation, scale);
    std::ostringstream key;
    key << tex.source << ' ' << webp << ' ' << srgb << ' ' << int(desc.wrap_u) << ' ' << int(desc.wrap_v)
        << ' ' << offset.x << ' ' << offset.y << ' ' << scale.x << ' ' << scale.y << ' ' << rotation << ' '
        << desc.texcoord;
    *cache_key = key.str();
    int source = tex.source;
    desc.image =
        webp >= 0 ? webp_image(webp, tex.source, srgb, tex_name, &source) : image(source, srgb, tex_name);
    if (!desc.image) return desc;
    if (from_webp) *from_webp = webp >= 0 && source == webp;
    const tinygltf::Image& img = m.images[size_t(source)];
    desc.path = img.uri.empty() ? src_.file + ": images[" + std::to_string(source) + "]" : img.uri;
    return desc;
}

/// EXT_texture_webp's image index, -1 without the extension.
int Materials::webp_source(const tinygltf::Texture& tex) const {
    auto it = tex.extensions.find("EXT_texture_webp");
    if (it == tex.extensions.end()) return -1;
    const double source = number(it->second, "source", -1);
    if (source < 0) return -1;
    // A huge index must not reach the int cast; image() names it as missing.
    return source < double(std::numeric_limits<int>::max()) ? int(source) : std::numeric_limits<int>::max();
}

/// The WebP image of a texture, or its `fallback` source when the WebP one
/// cannot be read (the extension's rule for optional use); `used` says which.
std::shared_ptr<const Image> Materials::webp_image(int webp, int fallback, bool srgb,
                                                   const std::string& tex_name, int* used) {
    const std::string element = tex_name + ".extensions.EXT_texture_webp";
    std::shared_ptr<const Image> result;
    std::string reason = "not found";
    try {
        result = image(webp, srgb, element);
    } catch (const InputError& e) {
        if (fallback < 0)
            throw input_error(src_.file, element, std::string("no fallback source: ") + e.what());
        reason = e.what();
    }
    *used = webp;
    if (result || fallback < 0) return result;
    log_warning(src_.file + ": " + element + ": WebP image " + std::to_string(webp) + " unreadable (" +
                reason + "), fallback images[" + std::to_string(fallback) + "] used");
    *used = fallback;
    return image(fallback, srgb, tex_name);
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
