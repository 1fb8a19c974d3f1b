#include "io/scene_parser.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "base/error.h"
#include "io/files.h"
#include "io/image_io.h"
#include "io/scene_parser_internal.h"

namespace sahara {

namespace {

// --- render ------------------------------------------------------------------

void parse_render(JsonObject o, RenderSettings& r) {
    if (auto v = o.get("width")) r.width = int(v->integer(1, 32768));
    if (auto v = o.get("height")) r.height = int(v->integer(1, 32768));
    if (auto v = o.get("spp")) r.spp = int(v->integer(1, INT32_MAX));
    // Deeper paths than this carry no visible energy and only risk deep recursion.
    if (auto v = o.get("max_depth")) r.max_depth = int(v->integer(1, 1024));
    if (auto v = o.get("seed")) r.seed = v->unsigned_integer();
    if (auto v = o.get("integrator"))
        r.integrator =
            IntegratorType(v->one_of({"path", "whitted", "albedo", "normals", "depth", "bvh-cost"}));
    if (auto v = o.get_non_null("time_limit_s")) r.time_limit_s = v->number(NumberRange::positive());
    if (auto v = o.get_non_null("target_error")) r.target_error = v->number(NumberRange::positive());
    // 2^±64 already saturates or blacks out any image; larger values are typos.
    if (auto v = o.get("exposure")) r.exposure = v->number_f(NumberRange::closed(-64, 64));
    if (auto v = o.get("tonemap")) r.tonemap = Tonemap(v->one_of({"clamp", "reinhard", "aces", "filmic"}));
    // Same order as BvhBuilder.
    if (auto v = o.get("bvh_builder"))
        r.bvh_builder = BvhBuilder(v->one_of({"binned", "sweep", "reinsert", "sbvh", "auto"}));
    o.finish();
}

// --- camera ------------------------------------------------------------------

/// The first of `keys` present in `o`, or nullptr.
const char* first_present(const JsonObject& o, std::initializer_list<const char*> keys) {
    for (const char* k : keys)
        if (o.has(k)) return k;
    return nullptr;
}

void parse_look_at_camera(JsonObject& o, const ParseContext& ctx, CameraDesc& cam) {
    JsonValue look = o.require("look_at", "the point [x, y, z] the camera looks at");
    cam.look_at = ctx.local_point(look.vec3d());
    if (length(cam.look_at - cam.position) == 0.0f) look.fail("look_at must differ from position");
    auto up = o.get("up");
    if (up) cam.up = normalize(up->nonzero_vec3());
    if (length(cross(normalize(cam.look_at - cam.position), cam.up)) < 1e-6f) {
        if (up) up->fail("up must not be parallel to the viewing direction");
        look.fail("the viewing direction is parallel to the default up [0, 0, 1]; give \"up\"");
    }
    if (auto v = o.get("vfov")) cam.vfov = v->number_f(NumberRange::open(0, 180));
}

void parse_euler_camera(JsonObject& o, CameraDesc& cam) {
    cam.euler_form = true;
    if (auto v = o.get("euler")) cam.euler = v->vec3();
    if (auto v = o.get("focal_length")) cam.focal_length = v->number_f(NumberRange::positive());
}

/// Reads the camera and, from its position, sets the scene's local origin.
void parse_camera(JsonObject o, ParseContext& ctx) {
    CameraDesc& cam = ctx.scene->camera;
    const char* look_key = first_present(o, {"look_at", "up", "vfov"});
    const char* euler_key = first_present(o, {"euler", "focal_length"});
    if (look_key && euler_key)
        o.value().fail(std::string("mixes the look-at form (\"") + look_key + "\") with the euler form (\"" +
                       euler_key + "\"); use either position/look_at/up/vfov or position/euler/focal_length");
    const Vec3d position = o.require("position", "the camera position [x, y, z]").vec3d();
    ctx.origin = ctx.scene->origin = choose_local_origin(position);
    cam.position = ctx.local_point(position);
    if (euler_key)
        parse_euler_camera(o, cam);
    else
        parse_look_at_camera(o, ctx, cam);
    if (auto v = o.get("aperture")) cam.aperture = v->number_f(NumberRange::non_negative());
    if (auto v = o.get_non_null("focus_distance")) cam.focus_distance = v->number_f(NumberRange::positive());
    // The euler form has no target; its natural focus is the view plane.
    if (cam.euler_form && !cam.focus_distance) cam.focus_distance = cam.focal_length;
    if (auto v = o.get("shutter")) {
        auto s = v->array(2, 2);
        cam.shutter_open = s[0].number_f();
        cam.shutter_close = s[1].number_f();
        if (cam.shutter_close < cam.shutter_open) v->fail_expected("[open, close] with open <= close");
    }
    o.finish();
}

// --- background ----------------------------------------------------------------

void parse_background(JsonObject o, ParseContext& ctx) {
    BackgroundDesc& bg = ctx.scene->background;
    bg.type = BackgroundDesc::Type(o.require("type", "\"constant\", \"gradient\" or \"envmap\"")
                                       .one_of({"constant", "gradient", "envmap"}));
    const NumberRange nonneg = NumberRange::non_negative();
    if (bg.type == BackgroundDesc::Type::constant) {
        if (auto v = o.get("color")) bg.color = v->vec3(nonneg);
    } else {
        if (auto v = o.get("up")) bg.up = normalize(v->nonzero_vec3());
    }
    if (bg.type == BackgroundDesc::Type::gradient) {
        if (auto v = o.get("bottom")) bg.bottom = v->vec3(nonneg);
        if (auto v = o.get("top")) bg.top = v->vec3(nonneg);
    }
    if (bg.type == BackgroundDesc::Type::envmap) {
        if (auto v = o.get("strength")) bg.strength = v->number_f(nonneg);
        JsonValue file = o.require("file", "the environment image file (lat-long)");
        std::filesystem::path path = ctx.resolve_existing(file);
        bg.file = path.string();
        try {
            bg.image = ctx.loaders->read_image(path, false);
        } catch (const InputError& e) {
            file.fail(e.what());
        }
    }
    o.finish();
}

// --- materials -------------------------------------------------------------------

/// [r, g, b], {"checker": {...}} or {"texture": "file"}; components in [0, 1].
ColorSource parse_color_source(const JsonValue& v, ParseContext& ctx) {
    const NumberRange unit = NumberRange::closed(0, 1);
    ColorSource c;
    if (v.json().is_array()) {
        c.color = v.vec3(unit);
        return c;
    }
    if (!v.json().is_object() || v.json().size() != 1)
        v.fail_expected("[r, g, b], {\"checker\": {...}} or {\"texture\": \"file\"}");
    JsonObject o(v);
    if (auto checker = o.get("checker")) {
        JsonObject co(*checker);
        c.kind = ColorSource::Kind::checker;
        if (auto e = co.get("even")) c.even = e->vec3(unit);
        if (auto e = co.get("odd")) c.odd = e->vec3(unit);
        if (auto e = co.get("scale")) c.checker_scale = e->number_f(NumberRange::positive());
        // Cells repeat every two along each axis; the remainder is exact in double.
        const double period = 2.0 * double(c.checker_scale);
        for (int i = 0; i < 3; ++i) c.checker_offset[i] = float(std::fmod(ctx.origin[i], period));
        co.finish();
    } else if (auto tex = o.get("texture")) {
        c.kind = ColorSource::Kind::texture;
        c.color = Rgb(1.0f);
        c.texture = ctx.texture(*tex, true);
    }
    o.finish();
    return c;
}

/// "alpha" and "alpha_cutoff" of the lambertian and unlit materials.
void parse_cutout(JsonObject& o, ParseContext& ctx, MaterialDesc& m) {
    if (auto v = o.get("alpha")) parse_alpha(*v, ctx, m);
    if (auto v = o.get("alpha_cutoff")) m.alpha_cutoff = v->number_f(NumberRange::closed(0, 1));
}

MaterialDesc parse_material(const std::string& name, JsonObject o, ParseContext& ctx) {
    MaterialDesc m;
    m.name = name;
    // The names in MaterialType's order.
    m.type = MaterialType(
        o.require("type", "\"lambertian\", \"metal\", \"dielectric\", \"emissive\", \"pbr\" or \"unlit\"")
            .one_of({"lambertian", "metal", "dielectric", "emissive", "pbr", "unlit"}));
    switch (m.type) {
        case MaterialType::lambertian:
            if (auto v = o.get("albedo")) m.albedo = parse_color_source(*v, ctx);
            parse_cutout(o, ctx, m);
            break;
        case MaterialType::metal:
            if (auto v = o.get("albedo")) m.albedo = parse_color_source(*v, ctx);
            if (auto v = o.get("roughness")) m.roughness = v->number_f(NumberRange::closed(0, 1));
            break;
        case MaterialType::dielectric:
            if (auto v = o.get("ior")) m.ior = v->number_f(NumberRange::positive());
            break;
        case MaterialType::emissive:
            if (auto v = o.get("radiance"))
                m.radiance.color = v->vec3(NumberRange::non_negative());
            else
                m.radiance.color = Rgb(1.0f);
            break;
        case MaterialType::pbr:
            parse_pbr_material(o, ctx, m);
            break;
        case MaterialType::unlit:
            m.albedo.color = Rgb(1.0f);  // glTF's default base colour, as for KHR_materials_unlit
            if (auto v = o.get("color")) m.albedo = parse_color_source(*v, ctx);
            parse_cutout(o, ctx, m);
            break;
    }
    o.finish();
    return m;
}

void parse_materials(JsonObject o, ParseContext& ctx) {
    // Duplicate names never reach here: parse_json_text rejects duplicate keys.
    for (const auto& [name, value] : o.value().json().items()) {
        JsonValue v(value, ctx.file, o.child_path(name));
        if (name == "default") v.fail("the name \"default\" is reserved for the built-in default material");
        if (name.empty()) v.fail("a material name must not be empty");
        o.get(name.c_str());
        ctx.material_by_name[name] = uint32_t(ctx.scene->materials.size());
        ctx.scene->materials.push_back(parse_material(name, JsonObject(v), ctx));
    }
}

}  // namespace

/// "alpha": number in [0, 1] or {"texture": "file"} (the image's alpha channel, linear).
void parse_alpha(const JsonValue& v, ParseContext& ctx, MaterialDesc& m) {
    if (v.json().is_number()) {
        m.alpha = v.number_f(NumberRange::closed(0, 1));
        return;
    }
    if (!v.json().is_object()) v.fail_expected("a number in [0, 1] or {\"texture\": \"file\"}");
    JsonObject o(v);
    m.alpha_texture = ctx.texture(o.require("texture", "the alpha image file"), false);
    o.finish();
}

// --- ParseContext ------------------------------------------------------------------

std::filesystem::path ParseContext::resolve_existing(const JsonValue& where) const {
    std::string name = where.string();
    if (name.empty()) where.fail_expected("a file name");
    std::filesystem::path path = base / name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) return path;
    if (std::filesystem::path(name).is_absolute()) where.fail("file not found: " + name);
    // Named outright: a dict from Python has no file, and its paths resolve against the cwd.
    const std::filesystem::path dir = base.empty() ? std::filesystem::current_path(ec)
                                                   : std::filesystem::absolute(base, ec).lexically_normal();
    where.fail("file not found: " + path.string() + " (relative paths resolve against " + dir.string() + ")");
}

int ParseContext::texture(const JsonValue& where, bool srgb) {
    std::filesystem::path path = resolve_existing(where);
    auto key = std::make_pair(path.lexically_normal().string(), srgb);
    if (auto it = texture_by_path.find(key); it != texture_by_path.end()) return it->second;
    TextureDesc t;
    t.path = path.string();
    try {
        t.image = loaders->read_image(path, srgb);
    } catch (const InputError& e) {
        where.fail(e.what());
    }
    int index = int(scene->textures.size());
    scene->textures.push_back(std::move(t));
    texture_by_path[key] = index;
    return index;
}

uint32_t ParseContext::material(const JsonValue& where) const {
    std::string name = where.string();
    if (name == "default") return 0;
    auto it = material_by_name.find(name);
    if (it != material_by_name.end()) return it->second;
    std::string known = "\"default\"";
    for (size_t i = 1; i < scene->materials.size(); ++i) known += ", \"" + scene->materials[i].name + "\"";
    where.fail("unknown material \"" + name + "\" (defined: " + known + ")");
}

// --- entry points --------------------------------------------------------------------

Vec3d choose_local_origin(const Vec3d& camera_position) {
    const Vec3d& c = camera_position;
    if (std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)}) < kLocalOriginRadius) return {0, 0, 0};
    const auto snap = [](double v) { return std::round(v / kLocalOriginGrid) * kLocalOriginGrid; };
    return {snap(c.x), snap(c.y), snap(c.z)};
}

SceneLoaders SceneLoaders::standard() {
    SceneLoaders l;
    l.load_model = [](const std::filesystem::path& f, const Mat4& m,
                      const std::optional<std::string>& variant) {
        return sahara::load_model(f, m, SharedMeshes::instance, variant);
    };
    l.read_image = [](const std::filesystem::path& f, bool srgb) { return sahara::read_image(f, srgb); };
    return l;
}

SceneDesc parse_scene_file(const std::filesystem::path& file) {
    return parse_scene_json(read_file(file, "scene file"), file);
}

SceneDesc parse_scene_json(const std::string& text, const std::filesystem::path& file) {
    return parse_scene_json(text, file, SceneLoaders::standard());
}

SceneDesc parse_scene_json(const std::string& text, const std::filesystem::path& file,
                           const SceneLoaders& loaders) {
    return parse_scene_value(parse_json_text(text, file.string()), file, loaders);
}

SceneDesc parse_scene_value(const Json& root_json, const std::filesystem::path& file) {
    return parse_scene_value(root_json, file, SceneLoaders::standard());
}

SceneDesc parse_scene_value(const Json& root_json, const std::filesystem::path& file,
                            const SceneLoaders& loaders) {
    SceneDesc scene;
    ParseContext ctx;
    ctx.file = file.string();
    ctx.base = file.parent_path();
    ctx.loaders = &loaders;
    ctx.scene = &scene;
    scene.source = ctx.file;
    scene.materials.push_back(default_material());

    JsonObject root(JsonValue(root_json, ctx.file, ""));
    if (auto v = root.get("format")) v->one_of({"scene/1"});
    if (auto v = root.get("render")) parse_render(JsonObject(*v), scene.render);
    parse_camera(JsonObject(root.require("camera", "the camera object")), ctx);
    if (auto v = root.get("background")) parse_background(JsonObject(*v), ctx);
    if (auto v = root.get("materials")) parse_materials(JsonObject(*v), ctx);
    if (auto v = root.get("lights")) parse_lights(ctx, *v);  // before the objects' model lights
    parse_objects(ctx, root.require("objects", "the array of objects"));
    root.finish();
    return scene;
}

SceneDesc default_scene() {
    SceneDesc s;
    s.source = "<default>";
    s.camera.position = Vec3(0, 0, 0);
    s.camera.look_at = Vec3(0, 1, 0);
    s.camera.up = Vec3(0, 0, 1);
    s.camera.vfov = 90.0f;
    s.background.type = BackgroundDesc::Type::gradient;
    s.background.bottom = Rgb(1, 1, 1);
    s.background.top = Rgb(0.5f, 0.7f, 1.0f);
    s.background.up = Vec3(0, 0, 1);
    s.materials.push_back(default_material());
    MaterialDesc red, green;
    red.name = "red";
    red.albedo.color = Rgb(0.8f, 0.1f, 0.1f);
    green.name = "green";
    green.albedo.color = Rgb(0.2f, 0.7f, 0.2f);
    s.materials.push_back(red);
    s.materials.push_back(green);
    s.spheres.push_back(SphereDesc{Vec3(0, 10, 0), 5.0f, 1, Vec3(0, 0, 0)});
    s.spheres.push_back(SphereDesc{Vec3(0, 10, -100), 95.0f, 2, Vec3(0, 0, 0)});
    return s;
}

}  // namespace sahara
