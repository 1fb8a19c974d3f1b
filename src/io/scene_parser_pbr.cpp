/// The scene format's `pbr` material: glTF 2.0 metallic-roughness with
/// textures (docs/scene-format.md, "pbr").
#include "io/scene_parser_internal.h"

namespace sahara {

namespace {

/// [r, g, b], or {"texture": FILE, "factor": [r, g, b]} (factor default 1).
ColorSource parse_pbr_color(const JsonValue& v, ParseContext& ctx, const NumberRange& range) {
    ColorSource c;
    if (v.json().is_array()) {
        c.color = v.vec3(range);
        return c;
    }
    if (!v.json().is_object()) v.fail_expected("[r, g, b] or {\"texture\": \"file\", \"factor\": [r, g, b]}");
    JsonObject o(v);
    c.kind = ColorSource::Kind::texture;
    c.texture = ctx.texture(o.require("texture", "the colour image file"), true);
    c.color = Rgb(1.0f);
    if (auto f = o.get("factor")) c.color = f->vec3(range);
    o.finish();
    return c;
}

/// {"texture": FILE} plus the extra numeric keys a map allows ("scale" for normal maps).
int parse_data_texture(const JsonValue& v, ParseContext& ctx, const char* what, float* scale) {
    if (!v.json().is_object())
        v.fail_expected(std::string("{\"texture\": \"file\"") + (scale ? ", \"scale\": s}" : "}"));
    JsonObject o(v);
    const int tex = ctx.texture(o.require("texture", what), false);  // data, not colour: linear
    if (scale)
        if (auto s = o.get("scale")) *scale = s->number_f();
    o.finish();
    return tex;
}

/// alpha_mode and its companions, with glTF's meaning: opaque ignores alpha,
/// mask cuts at alpha_cutoff, blend is stochastic transparency. Without an
/// alpha texture, the base colour texture's alpha is the alpha, as in glTF.
void parse_alpha_mode(JsonObject& o, ParseContext& ctx, MaterialDesc& m) {
    enum Mode : size_t { opaque, mask, blend };
    size_t mode = opaque;
    if (auto v = o.get("alpha_mode")) mode = v->one_of({"opaque", "mask", "blend"});
    std::optional<JsonValue> alpha = o.get("alpha"), cutoff = o.get("alpha_cutoff");
    if (cutoff && mode != mask) cutoff->fail("\"alpha_cutoff\" needs \"alpha_mode\": \"mask\"");
    if (mode == opaque) return;  // glTF OPAQUE: alpha is ignored
    if (alpha) parse_alpha(*alpha, ctx, m);
    if (m.alpha_texture < 0 && m.albedo.kind == ColorSource::Kind::texture)
        m.alpha_texture = m.albedo.texture;
    if (mode == mask) {
        m.alpha_cutoff = cutoff ? cutoff->number_f(NumberRange::closed(0, 1)) : 0.5f;
        // The filter only runs for cut-out materials: a constant alpha of 1 cuts nothing.
        if (m.alpha_texture < 0 && m.alpha >= *m.alpha_cutoff) m.alpha_cutoff.reset();
    }
}

/// clearcoat and sheen (glTF's KHR_materials_clearcoat and KHR_materials_sheen), factors only.
void parse_pbr_layers(JsonObject& o, PbrLayersDesc& l) {
    const NumberRange unit = NumberRange::closed(0, 1);
    if (auto v = o.get("clearcoat")) l.clearcoat = v->number_f(unit);
    if (auto v = o.get("clearcoat_roughness")) l.clearcoat_roughness = v->number_f(unit);
    if (auto v = o.get("sheen_color")) l.sheen_color = v->vec3(unit);
    if (auto v = o.get("sheen_roughness")) l.sheen_roughness = v->number_f(unit);
}

/// The thin film of glTF's KHR_materials_iridescence, factors only: one thickness (nm).
void parse_pbr_iridescence(JsonObject& o, IridescenceDesc& d) {
    if (auto v = o.get("iridescence")) d.factor = v->number_f(NumberRange::closed(0, 1));
    if (auto v = o.get("iridescence_ior")) d.ior = v->number_f(NumberRange::closed(1, 10));
    if (auto v = o.get("iridescence_thickness")) d.thickness_max = v->number_f(NumberRange::non_negative());
}

}  // namespace

void parse_pbr_material(JsonObject& o, ParseContext& ctx, MaterialDesc& m) {
    const NumberRange unit = NumberRange::closed(0, 1);
    m.albedo.color = Rgb(1.0f);  // glTF's default base colour
    m.roughness = 1.0f;          // and roughness, metallic (1) as MaterialDesc has it
    m.metallic = 1.0f;
    if (auto v = o.get("base_color")) m.albedo = parse_pbr_color(*v, ctx, unit);
    if (auto v = o.get("metallic")) m.metallic = v->number_f(unit);
    if (auto v = o.get("roughness")) m.roughness = v->number_f(unit);
    if (auto v = o.get("metallic_roughness"))
        m.metallic_roughness_texture = parse_data_texture(
            *v, ctx, "the metallic-roughness image file (G roughness, B metallic)", nullptr);
    if (auto v = o.get("normal_map"))
        m.normal_texture = parse_data_texture(*v, ctx, "the tangent-space normal map file", &m.normal_scale);
    float strength = 1.0f;
    if (auto v = o.get("emission")) m.radiance = parse_pbr_color(*v, ctx, NumberRange::non_negative());
    if (auto v = o.get("emission_strength")) strength = v->number_f(NumberRange::non_negative());
    m.radiance.color = m.radiance.color * strength;
    if (auto v = o.get("transmission")) m.transmission = v->number_f(unit);
    if (auto v = o.get("ior")) m.ior = v->number_f(NumberRange::closed(1, 10));
    if (auto v = o.get("thin_walled")) m.thin_walled = v->boolean();
    if (auto v = o.get("double_sided")) m.double_sided = v->boolean();
    parse_alpha_mode(o, ctx, m);
    parse_pbr_layers(o, m.layers);
    if (auto v = o.get("anisotropy")) m.anisotropy = v->number_f(unit);
    if (auto v = o.get("anisotropy_rotation")) m.anisotropy_rotation = v->number_f();
    parse_pbr_iridescence(o, m.iridescence);
    if (auto v = o.get("dispersion")) m.dispersion = v->number_f(NumberRange::non_negative());
    if (auto v = o.get("diffuse_transmission")) m.diffuse_transmission = v->number_f(unit);
    if (auto v = o.get("diffuse_transmission_color")) m.diffuse_transmission_color = v->vec3(unit);
}

}  // namespace sahara
