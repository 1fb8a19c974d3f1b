#include <doctest/doctest.h>

#include <string>

#include "scene_parser_test_util.h"

using namespace sahara;
using namespace sahara::parser_test;

namespace {

/// The scene's material 1 after parsing `material` (JSON object text) as "m".
MaterialDesc parse_one(const std::string& material, FakeLoaders* fake = nullptr) {
    FakeLoaders own;
    ScratchDir scratch;
    const SceneDesc d = parse_scene_json(with_objects("[]", R"({"m": )" + material + "}"),
                                         scratch.dir / "s.json", (fake ? fake : &own)->loaders());
    REQUIRE(d.materials.size() == 2);
    return d.materials[1];
}

}  // namespace

TEST_CASE("scene parser: pbr defaults are glTF's") {
    const MaterialDesc m = parse_one(R"({"type": "pbr"})");
    CHECK(m.type == MaterialType::pbr);
    CHECK(m.albedo.color == Rgb(1.0f));
    CHECK(m.metallic == 1.0f);
    CHECK(m.roughness == 1.0f);
    CHECK(m.ior == 1.5f);
    CHECK(m.transmission == 0.0f);
    CHECK(m.double_sided);
    CHECK(!m.thin_walled);
    CHECK(m.alpha == 1.0f);
    CHECK(!m.alpha_cutoff);
    CHECK(m.radiance.color == Rgb(0.0f));
}

TEST_CASE("scene parser: every pbr key reaches MaterialDesc") {
    FakeLoaders fake;
    const MaterialDesc m = parse_one(R"({"type": "pbr",
        "base_color": {"texture": "textures/wood.png", "factor": [0.5, 0.25, 1]},
        "metallic": 0.25, "roughness": 0.75,
        "metallic_roughness": {"texture": "textures/leaf.png"},
        "normal_map": {"texture": "textures/leaf.png", "scale": 0.5},
        "emission": [2, 3, 4], "emission_strength": 2,
        "transmission": 0.5, "ior": 1.33, "thin_walled": true,
        "alpha": 0.5, "alpha_mode": "mask", "alpha_cutoff": 0.25,
        "double_sided": false})",
                                     &fake);
    CHECK(m.albedo.kind == ColorSource::Kind::texture);
    CHECK(m.albedo.color == Rgb(0.5f, 0.25f, 1.0f));
    CHECK(m.metallic == 0.25f);
    CHECK(m.roughness == 0.75f);
    CHECK(m.metallic_roughness_texture >= 0);
    CHECK(m.normal_texture == m.metallic_roughness_texture);  // one linear image, loaded once
    CHECK(m.normal_scale == 0.5f);
    CHECK(m.radiance.color == Rgb(4.0f, 6.0f, 8.0f));
    CHECK(m.transmission == 0.5f);
    CHECK(m.ior == doctest::Approx(1.33f));
    CHECK(m.thin_walled);
    CHECK(m.alpha == 0.5f);
    CHECK(m.alpha_cutoff == 0.25f);
    CHECK(m.alpha_texture == m.albedo.texture);  // glTF: alpha from the base colour texture
    CHECK(!m.double_sided);
    // The colour texture is decoded as sRGB, the data maps are linear.
    REQUIRE(fake.images.size() == 2);
    CHECK(fake.images[0] == std::pair<std::string, bool>("wood.png", true));
    CHECK(fake.images[1] == std::pair<std::string, bool>("leaf.png", false));
}

TEST_CASE("scene parser: pbr alpha modes") {
    CHECK(parse_one(R"({"type": "pbr", "alpha": 0.3})").alpha == 1.0f);  // opaque ignores alpha
    const MaterialDesc blend = parse_one(R"({"type": "pbr", "alpha": 0.3, "alpha_mode": "blend"})");
    CHECK(blend.alpha == 0.3f);
    CHECK(!blend.alpha_cutoff);
    const MaterialDesc mask = parse_one(R"({"type": "pbr", "alpha": 0.3, "alpha_mode": "mask"})");
    CHECK(mask.alpha_cutoff == 0.5f);
    // A constant alpha above the cutoff cuts nothing: no filter needed.
    CHECK(!parse_one(R"({"type": "pbr", "alpha_mode": "mask"})").alpha_cutoff);
}

TEST_CASE("scene parser: bad pbr keys are named with their path") {
    const auto bad = [](const std::string& material) {
        return error_of(with_objects("[]", R"({"m": )" + material + "}"));
    };
    check_contains(bad(R"({"type": "pbr", "metallic": 1.5})"), {"materials.m.metallic", "[0, 1]"});
    check_contains(bad(R"({"type": "pbr", "roughness": -0.1})"), {"materials.m.roughness"});
    check_contains(bad(R"({"type": "pbr", "ior": 0.5})"), {"materials.m.ior"});
    check_contains(bad(R"({"type": "pbr", "base_color": [1, 2, 0]})"), {"materials.m.base_color"});
    check_contains(bad(R"({"type": "pbr", "base_color": {"factor": [1, 1, 1]}})"), {"texture"});
    check_contains(bad(R"({"type": "pbr", "base_color": {"texture": "nope.png"}})"), {"nope.png"});
    check_contains(bad(R"({"type": "pbr", "normal_map": {"texture": "textures/leaf.png", "scal": 1}})"),
                   {"scal"});
    check_contains(bad(R"({"type": "pbr", "alpha_mode": "clip"})"), {"opaque", "mask", "blend"});
    check_contains(bad(R"({"type": "pbr", "alpha_cutoff": 0.5})"), {"alpha_mode"});
    check_contains(bad(R"({"type": "pbr", "double_sided": 1})"), {"materials.m.double_sided"});
    check_contains(bad(R"({"type": "pbr", "albedo": [1, 1, 1]})"), {"albedo"});
    check_contains(bad(R"({"type": "pbr", "emission": [-1, 0, 0]})"), {"materials.m.emission"});
    check_contains(bad(R"({"type": "plastic"})"), {"pbr"});
}

TEST_CASE("scene parser: pbr clearcoat and sheen keys") {
    const MaterialDesc plain = parse_one(R"({"type": "pbr"})");
    CHECK_FALSE(plain.layers.any());
    const MaterialDesc m = parse_one(
        R"({"type": "pbr", "clearcoat": 0.75, "clearcoat_roughness": 0.25, "sheen_color": [1, 0.5, 0], "sheen_roughness": 0.5})");
    CHECK(m.layers.clearcoat == 0.75f);
    CHECK(m.layers.clearcoat_roughness == 0.25f);
    CHECK(m.layers.sheen_color == Rgb(1.0f, 0.5f, 0.0f));
    CHECK(m.layers.sheen_roughness == 0.5f);
    CHECK(m.layers.any());
    const auto bad = [](const std::string& material) {
        return error_of(with_objects("[]", R"({"m": )" + material + "}"));
    };
    check_contains(bad(R"({"type": "pbr", "clearcoat": 2})"), {"materials.m.clearcoat", "[0, 1]"});
    check_contains(bad(R"({"type": "pbr", "clearcoat_roughness": -1})"), {"materials.m.clearcoat_roughness"});
    check_contains(bad(R"({"type": "pbr", "sheen_color": [0, 0, 1.5]})"), {"materials.m.sheen_color"});
    check_contains(bad(R"({"type": "pbr", "sheen_roughness": "rough"})"), {"materials.m.sheen_roughness"});
    check_contains(bad(R"({"type": "lambertian", "clearcoat": 1})"), {"clearcoat"});  // pbr only
}

TEST_CASE("scene parser: pbr anisotropy keys") {
    const MaterialDesc plain = parse_one(R"({"type": "pbr"})");
    CHECK(plain.anisotropy == 0.0f);
    CHECK(plain.anisotropy_rotation == 0.0f);
    const MaterialDesc m = parse_one(R"({"type": "pbr", "anisotropy": 0.6, "anisotropy_rotation": 1.25})");
    CHECK(m.anisotropy == 0.6f);
    CHECK(m.anisotropy_rotation == 1.25f);
    CHECK(m.anisotropy_texture == -1);
    const auto bad = [](const std::string& material) {
        return error_of(with_objects("[]", R"({"m": )" + material + "}"));
    };
    check_contains(bad(R"({"type": "pbr", "anisotropy": 1.5})"), {"materials.m.anisotropy", "[0, 1]"});
    check_contains(bad(R"({"type": "pbr", "anisotropy": -0.1})"), {"materials.m.anisotropy"});
    check_contains(bad(R"({"type": "pbr", "anisotropy_rotation": "left"})"),
                   {"materials.m.anisotropy_rotation"});
    check_contains(bad(R"({"type": "metal", "anisotropy": 0.5})"), {"anisotropy"});  // pbr only
}

TEST_CASE("scene parser: pbr iridescence keys") {
    const MaterialDesc plain = parse_one(R"({"type": "pbr"})");
    CHECK_FALSE(plain.iridescence.any());
    const MaterialDesc m = parse_one(
        R"({"type": "pbr", "iridescence": 0.8, "iridescence_ior": 1.6, "iridescence_thickness": 320})");
    CHECK(m.iridescence.factor == 0.8f);
    CHECK(m.iridescence.ior == 1.6f);
    CHECK(m.iridescence.thickness_max == 320.0f);
    CHECK(m.iridescence.texture == -1);
    CHECK(m.iridescence.thickness_texture == -1);
    const auto bad = [](const std::string& material) {
        return error_of(with_objects("[]", R"({"m": )" + material + "}"));
    };
    check_contains(bad(R"({"type": "pbr", "iridescence": 1.5})"), {"materials.m.iridescence", "[0, 1]"});
    check_contains(bad(R"({"type": "pbr", "iridescence_ior": 0.5})"), {"materials.m.iridescence_ior"});
    check_contains(bad(R"({"type": "pbr", "iridescence_thickness": -1})"),
                   {"materials.m.iridescence_thickness"});
    check_contains(bad(R"({"type": "lambertian", "iridescence": 0.5})"), {"iridescence"});  // pbr only
}

TEST_CASE("scene parser: pbr dispersion and diffuse transmission keys") {
    const MaterialDesc plain = parse_one(R"({"type": "pbr"})");
    CHECK(plain.dispersion == 0.0f);
    CHECK(plain.diffuse_transmission == 0.0f);
    const MaterialDesc m = parse_one(
        R"({"type": "pbr", "dispersion": 0.7, "diffuse_transmission": 0.4, "diffuse_transmission_color": [1, 0.5, 0.2]})");
    CHECK(m.dispersion == 0.7f);
    CHECK(m.diffuse_transmission == 0.4f);
    CHECK(m.diffuse_transmission_color == Rgb(1.0f, 0.5f, 0.2f));
    CHECK(m.diffuse_transmission_texture == -1);
    const auto bad = [](const std::string& material) {
        return error_of(with_objects("[]", R"({"m": )" + material + "}"));
    };
    check_contains(bad(R"({"type": "pbr", "dispersion": -1})"), {"materials.m.dispersion"});
    check_contains(bad(R"({"type": "pbr", "diffuse_transmission": 2})"),
                   {"materials.m.diffuse_transmission", "[0, 1]"});
    check_contains(bad(R"({"type": "pbr", "diffuse_transmission_color": [1, 2, 0]})"),
                   {"materials.m.diffuse_transmission_color"});
    check_contains(bad(R"({"type": "lambertian", "dispersion": 0.5})"), {"dispersion"});  // pbr only
}
