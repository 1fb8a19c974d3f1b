#include "base/text.h"
#include "pipeline/material_info.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sahara {

namespace {

const char* material_type_name(MaterialType t) {
    switch (t) {
        case MaterialType::lambertian:
            return "lambertian";
        case MaterialType::metal:
            return "metal";
        case MaterialType::dielectric:
            return "dielectric";
        case MaterialType::emissive:
            return "emissive";
        case MaterialType::pbr:
            return "pbr";
        case MaterialType::unlit:
            return "unlit";
    }
    return "?";
}

std::string number_text(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", double(v));
    return buf;
}

/// Texture roles in the order a reader expects them: {role, texture index}.
std::vector<std::pair<std::string, int>> textures_of(const MaterialDesc& m) {
    std::vector<std::pair<std::string, int>> out;
    for_each_texture_slot(m, [&](const char* role, int t) {
        const std::string_view r = role;
        if (t < 0) return;
        if (r == "base colour" && m.albedo.kind != ColorSource::Kind::texture) return;
        if (r == "emission" && m.radiance.kind != ColorSource::Kind::texture) return;
        // glTF takes alpha from the base colour texture: name it only when it is another image.
        if (r == "alpha" && t == m.albedo.texture && m.albedo.kind == ColorSource::Kind::texture) return;
        out.emplace_back(role, t);
    });
    return out;
}

/// "opaque", "mask" (cut at alpha_cutoff) or "blend" (stochastic transparency).
const char* alpha_mode(const MaterialDesc& m) {
    if (m.alpha_cutoff) return "mask";
    return m.alpha < 1.0f || m.alpha_texture >= 0 || m.vertex_alpha ? "blend" : "opaque";
}

bool attenuates(const MaterialDesc& m) {
    return std::isfinite(m.attenuation_distance) && min_component(m.attenuation_color) < 1.0f;
}

/// One material's line: text and JSON say the same things.
/// pbr's clearcoat, sheen and anisotropy, when it has them.
void describe_layers(std::vector<std::string>& parts, nlohmann::json& value, const MaterialDesc& m) {
    const PbrLayersDesc& l = m.layers;
    const bool pbr = m.type == MaterialType::pbr;
    value["clearcoat"] = pbr ? l.clearcoat : 0.0f;
    if (pbr && l.clearcoat > 0.0f)
        parts.push_back("clearcoat " + number_text(l.clearcoat) + " (roughness " +
                        number_text(l.clearcoat_roughness) + ")");
    const bool sheen = pbr && max_component(l.sheen_color) > 0.0f;
    value["sheen_color"] = sheen ? std::vector<float>{l.sheen_color.x, l.sheen_color.y, l.sheen_color.z}
                                 : std::vector<float>{0.0f, 0.0f, 0.0f};
    if (sheen)
        parts.push_back("sheen [" + number_text(l.sheen_color.x) + ", " + number_text(l.sheen_color.y) +
                        ", " + number_text(l.sheen_color.z) + "] (roughness " +
                        number_text(l.sheen_roughness) + ")");
    const bool anisotropic = pbr && m.anisotropy > 0.0f;
    value["anisotropy"] = anisotropic ? m.anisotropy : 0.0f;
    if (anisotropic)
        parts.push_back("anisotropy " + number_text(m.anisotropy) + " (rotation " +
                        number_text(m.anisotropy_rotation) + ")");
}

void describe_material(StatsReport& s, const std::string& label, const MaterialDesc& m) {
    std::vector<std::string> parts{material_type_name(m.type)};
    nlohmann::json value = {{"name", m.name}, {"type", material_type_name(m.type)}};
    nlohmann::json textures = nlohmann::json::object();
    std::vector<std::string> roles;
    for (const auto& [role, index] : textures_of(m)) {
        roles.push_back(role);
        textures[role] = index;
    }
    if (!roles.empty()) parts.push_back("textures: " + join(roles, ", "));
    value["textures"] = textures;
    const bool pbr = m.type == MaterialType::pbr;
    // Every type but dielectric and emissive has an albedo that vertex colours tint.
    const bool tinted =
        m.vertex_colors && m.type != MaterialType::dielectric && m.type != MaterialType::emissive;
    value["vertex_colors"] = tinted;
    value["vertex_alpha"] = m.vertex_alpha;
    if (tinted) parts.push_back(m.vertex_alpha ? "vertex colours and alpha" : "vertex colours");
    value["emission"] = emits_light(m);
    if (emits_light(m) && m.type != MaterialType::emissive) parts.push_back("emission");
    const bool transmits = pbr && (m.transmission > 0.0f || m.transmission_texture >= 0);
    value["transmission"] = transmits ? m.transmission : 0.0f;
    if (transmits)
        parts.push_back("transmission " + number_text(m.transmission) +
                        (m.thin_walled ? " (thin-walled)" : ", ior " + number_text(m.ior)));
    value["volume_attenuation"] = transmits && !m.thin_walled && attenuates(m);
    if (value["volume_attenuation"] == true)
        parts.push_back("volume attenuation over " + number_text(m.attenuation_distance));
    const bool disperses = transmits && !m.thin_walled && m.dispersion > 0.0f;
    value["dispersion"] = disperses ? m.dispersion : 0.0f;
    if (disperses) parts.push_back("dispersion " + number_text(m.dispersion));
    const bool diffuse_transmits = pbr && m.diffuse_transmission > 0.0f;
    value["diffuse_transmission"] = diffuse_transmits ? m.diffuse_transmission : 0.0f;
    if (diffuse_transmits) parts.push_back("diffuse transmission " + number_text(m.diffuse_transmission));
    describe_layers(parts, value, m);
    const std::string alpha = alpha_mode(m);
    value["alpha_mode"] = alpha;
    if (m.alpha_cutoff) value["alpha_cutoff"] = *m.alpha_cutoff;
    if (alpha == "mask") parts.push_back("alpha mask " + number_text(*m.alpha_cutoff));
    if (alpha == "blend") parts.push_back("alpha blend");
    value["double_sided"] = m.double_sided;
    if (!m.double_sided) parts.push_back("one-sided");
    value["extensions"] = m.extensions;
    if (!m.extensions.empty()) parts.push_back("extensions: " + join(m.extensions, ", "));
    s.add("Materials", label, join(parts, "; "), value);
}

}  // namespace

bool emits_light(const MaterialDesc& m) {
    switch (m.type) {
        case MaterialType::emissive:
            return true;
        case MaterialType::pbr:
            return m.radiance.kind == ColorSource::Kind::texture || max_component(m.radiance.color) > 0.0f;
        case MaterialType::lambertian:
            return max_component(m.emission) > 0.0f;
        default:
            return false;
    }
}

void describe_materials(StatsReport& s, const SceneDesc& d) {
    s.add_count("Materials", "Total", d.materials.size());
    for (MaterialType t : {MaterialType::lambertian, MaterialType::metal, MaterialType::dielectric,
                           MaterialType::emissive, MaterialType::pbr, MaterialType::unlit})
        s.add_count("Materials", material_type_name(t),
                    uint64_t(std::count_if(d.materials.begin(), d.materials.end(),
                                           [t](const MaterialDesc& m) { return m.type == t; })));
    for (size_t i = 0; i < d.materials.size(); ++i) {
        const MaterialDesc& m = d.materials[i];
        std::string label("[");  // built piecewise: gcc 12 warns falsely (-Wrestrict) on a + chain here
        label.append(std::to_string(i)).append("] ").append(m.name);
        describe_material(s, label, m);
        std::vector<std::string> ignored = m.ignored;
        if (!ignored.empty()) s.add("Ignored inputs", label, join(ignored, ", "), ignored);
    }
}

}  // namespace sahara
