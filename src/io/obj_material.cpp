// MTL materials into sahara's materials (pbr where the MTL asks for more than a
// diffuse colour), MTL textures, and the text checks tinyobjloader leaves out.
#include "io/obj_material.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "base/error.h"
#include "base/log.h"
#include "io/image_io.h"

namespace sahara::obj {

namespace {

/// Lines of `text` with their 1-based numbers, without the line break.
template <class F>
void for_each_line(const std::string& text, F&& f) {
    size_t pos = 0, number = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string_view line(text.data() + pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        f(std::string_view(line.substr(0, line.find('#'))), ++number);  // comments may say anything
        pos = end + 1;
    }
}

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (true) {
        i = line.find_first_not_of(" \t", i);
        if (i == std::string_view::npos) return out;
        const size_t end = std::min(line.find_first_of(" \t", i), line.size());
        out.push_back(line.substr(i, end - i));
        i = end;
    }
}

/// Warns, with file and line, when `word` is not a whole number (tinyobjloader
/// would read only its valid start, e.g. 3.1 of "3.1+e2"). At most 10 warnings a file.
class NumberChecker {
   public:
    explicit NumberChecker(std::string file) : file_(std::move(file)) {}
    ~NumberChecker() {
        if (count_ > kShown)
            log_warning(file_ + ": " + std::to_string(count_ - kShown) + " more malformed numbers");
    }
    void check(std::string_view word, size_t line) {
        double value = 0.0;
        const char* begin = word.data() + (!word.empty() && word[0] == '+' ? 1 : 0);
        const auto [end, ec] = std::from_chars(begin, word.data() + word.size(), value);
        if (ec == std::errc() && end == word.data() + word.size()) return;
        if (++count_ > kShown) return;
        std::ostringstream read;
        if (ec == std::errc())
            read << "read as " << value;
        else
            read << "not a number";
        log_warning(file_ + ": line " + std::to_string(line) + ": malformed number '" + std::string(word) +
                    "', " + read.str());
    }

   private:
    static constexpr size_t kShown = 10;
    std::string file_;
    size_t count_ = 0;
};

bool has_non_finite_word(std::string_view word) {
    return word.find_first_of("nNiI") != std::string_view::npos;
}

/// MTL keywords whose arguments are plain numbers.
const std::set<std::string> kNumericMtlKeys = {"ka", "kd", "ks", "ke", "tf", "ns",  "ni",   "d",
                                               "tr", "pr", "pm", "ps", "pc", "pcr", "illum"};

Rgb to_rgb(const tinyobj::real_t* c) { return Rgb(float(c[0]), float(c[1]), float(c[2])); }

/// map_d images are usually grey without an alpha channel: then the grey
/// value is the alpha (MaterialDesc reads a texture's alpha channel).
std::shared_ptr<const Image> alpha_from_grey(std::shared_ptr<const Image> img) {
    for (size_t i = 3; i < img->rgba.size(); i += 4)
        if (img->rgba[i] != 1.0f) return img;
    auto out = std::make_shared<Image>(*img);
    for (size_t i = 0; i + 3 < out->rgba.size(); i += 4) out->rgba[i + 3] = out->rgba[i];
    return out;
}

/// A tangent-space normal map is bluish with red and green around 0.5; anything
/// else given as map_Bump/bump is a height map.
bool looks_like_normal_map(const Image& img) {
    double r = 0, g = 0, b = 0;
    const size_t n = img.rgba.size() / 4;
    for (size_t i = 0; i < n; ++i) {
        r += double(img.rgba[4 * i]);
        g += double(img.rgba[4 * i + 1]);
        b += double(img.rgba[4 * i + 2]);
    }
    if (n == 0) return false;
    r /= double(n), g /= double(n), b /= double(n);
    return b > 0.6 && std::abs(r - 0.5) < 0.15 && std::abs(g - 0.5) < 0.15;
}

/// Height map (red channel, times `multiplier`) -> tangent-space normal map in
/// glTF's convention (+Y towards the image top). The map's full range is taken
/// as a relief 1/64 of the texture's width deep, so slopes keep with resolution.
std::shared_ptr<const Image> normals_from_height(const Image& h, float multiplier) {
    auto out = std::make_shared<Image>(h);
    const int w = h.width, ht = h.height;
    auto at = [&](int x, int y) {
        x = (x % w + w) % w, y = (y % ht + ht) % ht;  // bump maps tile
        return h.rgba[4 * (size_t(y) * size_t(w) + size_t(x))];
    };
    const float k = multiplier * float(w) / 64.0f * 0.5f;  // 0.5: central differences span two texels
    for (int y = 0; y < ht; ++y)
        for (int x = 0; x < w; ++x) {
            const float du = (at(x + 1, y) - at(x - 1, y)) * k;
            const float dv = (at(x, y - 1) - at(x, y + 1)) * k;  // row 0 is the top: up is y - 1
            const Vec3 n = normalize(Vec3(-du, -dv, 1.0f));
            float* px = &out->rgba[4 * (size_t(y) * size_t(w) + size_t(x))];
            px[0] = 0.5f * n.x + 0.5f, px[1] = 0.5f * n.y + 0.5f, px[2] = 0.5f * n.z + 0.5f, px[3] = 1.0f;
        }
    return out;
}

/// Nearest texel of `img` at the same relative position as (x, y) of a w x h image.
float channel_at(const Image& img, int x, int y, int w, int h) {
    const int sx = std::min(img.width - 1, x * img.width / w),
              sy = std::min(img.height - 1, y * img.height / h);
    return img.rgba[4 * (size_t(sy) * size_t(img.width) + size_t(sx))];
}

}  // namespace

void check_encoding(const std::string& file, const std::string& text) {
    auto starts = [&](std::initializer_list<unsigned char> bom) {
        return text.size() >= bom.size() &&
               std::equal(bom.begin(), bom.end(), text.begin(),
                          [](unsigned char a, char b) { return a == static_cast<unsigned char>(b); });
    };
    const char* name = starts({0xFF, 0xFE, 0, 0})   ? "UTF-32 (little-endian)"
                       : starts({0, 0, 0xFE, 0xFF}) ? "UTF-32 (big-endian)"
                       : starts({0xFF, 0xFE})       ? "UTF-16 (little-endian)"
                       : starts({0xFE, 0xFF})       ? "UTF-16 (big-endian)"
                                                    : nullptr;
    if (name)
        throw input_error(file, "",
                          std::string("is ") + name +
                              " text; OBJ and MTL files are read as ASCII/UTF-8 (convert it, e.g. "
                              "iconv -f UTF-16 -t UTF-8)");
}

void check_obj_numbers(const std::string& file, const std::string& text) {
    NumberChecker checker(file);
    size_t counts[3] = {0, 0, 0};
    const char* names[3] = {"v", "vt", "vn"};
    for_each_line(text, [&](std::string_view line, size_t number) {
        const std::vector<std::string_view> w = words(line);
        if (w.empty()) return;
        const int kind = w[0] == "v" ? 0 : w[0] == "vt" ? 1 : w[0] == "vn" ? 2 : -1;
        if (kind < 0) return;
        ++counts[kind];
        for (size_t i = 1; i < w.size(); ++i) {
            const bool colour = kind == 0 && w.size() == 7 && i >= 4;  // v x y z r g b
            if (has_non_finite_word(w[i]))
                throw input_error(
                    file, std::string(names[kind]) + " #" + std::to_string(counts[kind]),
                    colour ? "colour is not a finite number" : "coordinate is not a finite number");
            checker.check(w[i], number);
        }
    });
}

MtlKeys scan_mtl(const std::string& file, const std::string& text) {
    check_encoding(file, text);
    NumberChecker checker(file);
    MtlKeys keys;
    std::string current;
    for_each_line(text, [&](std::string_view line, size_t number) {
        const std::vector<std::string_view> w = words(line);
        if (w.empty()) return;
        std::string key(w[0]);
        std::transform(key.begin(), key.end(), key.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (key == "newmtl") {
            current = w.size() > 1 ? std::string(line.substr(line.find(w[1]))) : "";
            while (!current.empty() && (current.back() == ' ' || current.back() == '\t')) current.pop_back();
            return;
        }
        keys[current].insert(key);
        if (!kNumericMtlKeys.count(key) ||
            (w.size() > 1 && std::isalpha(static_cast<unsigned char>(w[1][0]))))
            return;  // texture options, or "Kd spectral ..." / "Kd xyz ..."
        for (size_t i = 1; i < w.size(); ++i) checker.check(w[i], number);
    });
    return keys;
}

int ObjTextures::get(const std::string& name, const tinyobj::texture_option_t& opt, Use use,
                     const std::string& what) {
    std::string portable = name;
    std::replace(portable.begin(), portable.end(), '\\', '/');
    while (portable.rfind("./", 0) == 0) portable.erase(0, 2);
    const std::filesystem::path path = dir_ / std::filesystem::path(portable);
    const auto key = std::make_pair(path.string(), int(use));
    if (auto it = cache_.find(key); it != cache_.end()) return it->second;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        log_warning(path.string() + ": " + what + " texture not found, material falls back to its colour");
        return cache_[key] = -1;
    }
    std::shared_ptr<const Image> img = read_image(path, use == Use::color);
    if (use == Use::alpha) img = alpha_from_grey(img);
    if (use == Use::bump && !looks_like_normal_map(*img))
        img = normals_from_height(*img, float(opt.bump_multiplier));
    return cache_[key] = add(std::move(img), path.string(), opt);
}

int ObjTextures::add(std::shared_ptr<const Image> image, const std::string& path,
                     const tinyobj::texture_option_t& opt) {
    TextureDesc tex;
    tex.path = path;
    tex.image = std::move(image);
    tex.wrap_u = tex.wrap_v = opt.clamp ? WrapMode::clamp : WrapMode::repeat;
    tex.uv_offset = {float(opt.origin_offset[0]), float(opt.origin_offset[1])};
    tex.uv_scale = {float(opt.scale[0]), float(opt.scale[1])};
    model_.textures.push_back(std::move(tex));
    return int(model_.textures.size()) - 1;
}

int ObjTextures::metallic_roughness(const tinyobj::material_t& m) {
    const int r = m.roughness_texname.empty()
                      ? -1
                      : get(m.roughness_texname, m.roughness_texopt, Use::data, "map_Pr of " + m.name);
    const int k = m.metallic_texname.empty()
                      ? -1
                      : get(m.metallic_texname, m.metallic_texopt, Use::data, "map_Pm of " + m.name);
    if (r < 0 && k < 0) return -1;
    const Image* rough = r >= 0 ? model_.textures[size_t(r)].image.get() : nullptr;
    const Image* metal = k >= 0 ? model_.textures[size_t(k)].image.get() : nullptr;
    const Image& size =
        rough && (!metal || rough->width * rough->height >= metal->width * metal->height) ? *rough : *metal;
    auto packed = std::make_shared<Image>();
    packed->width = size.width, packed->height = size.height;
    packed->rgba.assign(size_t(size.width) * size_t(size.height) * 4, 1.0f);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            float* px = &packed->rgba[4 * (size_t(y) * size_t(size.width) + size_t(x))];
            if (rough) px[1] = channel_at(*rough, x, y, size.width, size.height);
            if (metal) px[2] = channel_at(*metal, x, y, size.width, size.height);
        }
    const int from = r >= 0 ? r : k;
    const std::string path = model_.textures[size_t(from)].path;
    return add(std::move(packed), path, r >= 0 ? m.roughness_texopt : m.metallic_texopt);
}

namespace {

/// Anything beyond a diffuse colour, an emission and a cut-out makes an MTL material pbr.
bool needs_pbr(const tinyobj::material_t& m, const std::set<std::string>& keys) {
    for (const char* k : {"pr", "pm", "map_pr", "map_pm", "norm", "map_bump", "bump"})
        if (keys.count(k)) return true;
    return max_component(to_rgb(m.specular)) > 0.0f && m.illum != 1 && m.illum != 0;
}

/// Ke x map_Ke (a map without Ke emits the map itself).
ColorSource emission(const tinyobj::material_t& m, ObjTextures& textures) {
    ColorSource out{ColorSource::Kind::constant, Rgb(0.0f)};
    const Rgb ke = to_rgb(m.emission);
    int tex = -1;
    if (!m.emissive_texname.empty())
        tex = textures.get(m.emissive_texname, m.emissive_texopt, ObjTextures::Use::color,
                           "map_Ke of " + m.name);
    if (!(max_component(ke) > 0.0f) && tex < 0) return out;
    out.color = max_component(ke) > 0.0f ? ke : Rgb(1.0f);
    if (tex >= 0) out.kind = ColorSource::Kind::texture, out.texture = tex;
    return out;
}

/// The pbr parameters: specular colour and exponent of classic MTL become
/// metallic and roughness (docs/scene-format.md); the PBR extension is taken as written.
void set_pbr(MaterialDesc& out, const tinyobj::material_t& m, const std::set<std::string>& keys,
             ObjTextures& textures) {
    out.type = MaterialType::pbr;
    const Rgb ks = to_rgb(m.specular);
    const bool specular = max_component(ks) > 0.0f && m.illum != 1 && m.illum != 0;
    const bool extension =
        keys.count("pr") || keys.count("pm") || keys.count("map_pr") || keys.count("map_pm");
    out.metallic = keys.count("pm") ? std::clamp(float(m.metallic), 0.0f, 1.0f) : 0.0f;
    out.roughness = 1.0f;
    if (keys.count("pr"))
        out.roughness = std::clamp(float(m.roughness), 0.0f, 1.0f);
    else if (specular)  // Beckmann/Phong equivalence alpha = sqrt(2 / (Ns + 2)), roughness = sqrt(alpha)
        out.roughness = float(std::pow(2.0 / (std::max(0.0, double(float(m.shininess))) + 2.0), 0.25));
    if (!extension && specular && !(max_component(out.albedo.color) > 0.0f) &&
        out.albedo.kind == ColorSource::Kind::constant) {
        out.metallic = 1.0f;  // black Kd and a specular colour: the classic way of writing a metal
        out.albedo.color = ks;
    }
    out.metallic_roughness_texture = textures.metallic_roughness(m);
    if (out.metallic_roughness_texture >= 0) {  // the maps replace the numbers, as map_Kd replaces Kd
        if (!m.roughness_texname.empty()) out.roughness = 1.0f;
        if (!m.metallic_texname.empty()) out.metallic = 1.0f;
    }
    if (keys.count("ni") && float(m.ior) > 1.0f) out.ior = float(m.ior);
    if (!m.normal_texname.empty()) {
        out.normal_texture =
            textures.get(m.normal_texname, m.normal_texopt, ObjTextures::Use::data, "norm of " + m.name);
        out.normal_scale = float(m.normal_texopt.bump_multiplier);
    } else if (!m.bump_texname.empty()) {
        out.normal_texture =
            textures.get(m.bump_texname, m.bump_texopt, ObjTextures::Use::bump, "map_Bump of " + m.name);
    }
}

/// MTL inputs with no counterpart in sahara's material, named by their keyword
/// for `sahara info` (ambient Ka is left out: nearly every file writes it).
std::vector<std::string> ignored_inputs(const tinyobj::material_t& m) {
    std::vector<std::string> out;
    const std::pair<const std::string*, const char*> maps[] = {{&m.ambient_texname, "map_Ka"},
                                                               {&m.specular_texname, "map_Ks"},
                                                               {&m.specular_highlight_texname, "map_Ns"},
                                                               {&m.displacement_texname, "disp"},
                                                               {&m.reflection_texname, "refl"},
                                                               {&m.sheen_texname, "map_Ps"}};
    for (const auto& [name, key] : maps)
        if (!name->empty()) out.push_back(key);
    if (m.sheen > 0) out.push_back("Ps (sheen)");
    if (m.clearcoat_thickness > 0) out.push_back("Pc (clearcoat)");
    if (m.anisotropy > 0) out.push_back("aniso (anisotropy)");
    return out;
}

}  // namespace

MaterialDesc convert_material(const tinyobj::material_t& m, const std::set<std::string>& keys,
                              ObjTextures& textures) {
    MaterialDesc out;
    out.name = m.name;
    out.albedo.color = to_rgb(m.diffuse);
    if (!m.diffuse_texname.empty()) {
        const int t =
            textures.get(m.diffuse_texname, m.diffuse_texopt, ObjTextures::Use::color, "map_Kd of " + m.name);
        if (t >= 0) out.albedo = {ColorSource::Kind::texture, Rgb(1.0f), {}, {}, 1.0f, t, {}};
    }
    out.alpha = std::clamp(float(m.dissolve), 0.0f, 1.0f);
    if (!m.alpha_texname.empty())
        out.alpha_texture =
            textures.get(m.alpha_texname, m.alpha_texopt, ObjTextures::Use::alpha, "map_d of " + m.name);
    const ColorSource glow = emission(m, textures);
    const bool emits = glow.kind == ColorSource::Kind::texture || max_component(glow.color) > 0.0f;
    if (needs_pbr(m, keys) || (emits && out.albedo.kind == ColorSource::Kind::texture)) {
        set_pbr(out, m, keys, textures);
        out.radiance = glow;
    } else if (emits) {  // a plain light source keeps rendering as before
        out.type = MaterialType::emissive;
        out.radiance = glow;
    }
    out.ignored = ignored_inputs(m);
    return out;
}

}  // namespace sahara::obj
