#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "render/bsdf_pbr.h"
#include "render_test_util.h"
#include "scene/tangents.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc white_pbr() {
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = Rgb(1.0f);
    m.metallic = 0;
    m.roughness = 0.5f;
    return m;
}

/// A texture of w x 1 texels with the given RGB colours (alpha 1).
TextureDesc strip(std::initializer_list<Rgb> texels, int texcoord = 0) {
    auto img = std::make_shared<Image>();
    img->width = int(texels.size());
    img->height = 1;
    for (const Rgb& c : texels) img->rgba.insert(img->rgba.end(), {c.x, c.y, c.z, 1.0f});
    TextureDesc t;
    t.image = img;
    t.wrap_u = t.wrap_v = WrapMode::clamp;
    t.texcoord = texcoord;
    return t;
}

/// A unit square in z = 0 facing +z, UVs = xy, with material 1.
TriangleMesh square() {
    TriangleMesh m;
    m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = 1;
    return m;
}

SurfaceInteraction flat_hit() {
    SurfaceInteraction si;
    si.ng = si.ns = Vec3(0, 0, 1);
    si.uv = {0.25f, 0.5f};
    si.uv1 = {0.75f, 0.5f};
    return si;
}

/// The albedo image's value at the square's point (x, y) seen from above.
Rgb albedo_at(SceneDesc d, float x, float y) {
    d.render.integrator = IntegratorType::albedo;
    const Scene scene = build_scene(d);
    Sampler s(1, SamplerType::independent);
    s.start(0, 0, 0);
    return estimate_radiance(scene, Ray{{x, y, 1}, {0, 0, -1}, 0.0f, kInfinity, 0.0f}, s, 4);
}

}  // namespace

TEST_CASE("pbr inputs: vertex colours multiply the base colour") {
    SceneDesc d = empty_scene(Rgb(0.0f));
    MaterialDesc m = white_pbr();
    m.albedo.color = Rgb(0.5f, 1.0f, 1.0f);
    d.materials.push_back(m);
    TriangleMesh mesh = square();
    mesh.colors = {Rgb(1, 0, 0), Rgb(1, 0, 0), Rgb(0, 0, 1), Rgb(0, 0, 1)};
    d.meshes.push_back(mesh);
    const Rgb c = albedo_at(d, 0.9f, 0.2f);  // inside triangle 0, barycentric mix of red and blue
    CHECK(c.x == doctest::Approx(0.5f * 0.8f).epsilon(1e-3));
    CHECK(c.y == doctest::Approx(0.0f));
    CHECK(c.z == doctest::Approx(0.2f).epsilon(1e-3));
    // A second mesh without colours stays white.
    TriangleMesh plain = square();
    for (Vec3& p : plain.positions) p += Vec3(2, 0, 0);
    d.meshes.push_back(plain);
    CHECK(albedo_at(d, 2.5f, 0.5f) == Rgb(0.5f, 1.0f, 1.0f));
}

TEST_CASE("pbr inputs: metallic-roughness texture scales by G and B, each texture reads its UV set") {
    std::vector<TextureDesc> textures = {strip({Rgb(0, 0.5f, 0.25f)}),
                                         strip({Rgb(1, 0, 0), Rgb(0, 1, 0)}, 1)};
    MaterialDesc m = white_pbr();
    m.metallic = 0.8f;
    m.roughness = 0.6f;
    m.metallic_roughness_texture = 0;
    m.albedo.kind = ColorSource::Kind::texture;
    m.albedo.color = Rgb(1.0f);
    m.albedo.texture = 1;  // reads uv1 = (0.75, .): the green texel
    const Bsdf b = make_bsdf(m, flat_hit(), textures);
    CHECK(b.kind == BsdfKind::pbr);
    CHECK(b.roughness == doctest::Approx(0.3f));
    CHECK(b.metallic == doctest::Approx(0.2f));
    CHECK(b.albedo.x < 0.01f);
    CHECK(b.albedo.y > 0.99f);
    textures[1].texcoord = 0;  // now uv = (0.25, .): red
    CHECK(make_bsdf(m, flat_hit(), textures).albedo.x > 0.99f);
}

TEST_CASE("pbr inputs: normal maps bend the shading normal along the tangent frame") {
    const float s = std::sqrt(0.5f);
    // Encoded normal tilted 45 degrees towards +tangent, and one towards +bitangent.
    std::vector<TextureDesc> textures = {strip({Rgb(0.5f + 0.5f * s, 0.5f, 0.5f + 0.5f * s)}),
                                         strip({Rgb(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * s)})};
    MaterialDesc m = white_pbr();
    m.normal_texture = 0;
    SurfaceInteraction si = flat_hit();
    CHECK(make_bsdf(m, si, textures).frame.n.x == doctest::Approx(0.0f));  // no tangent: unchanged
    si.tangent = Vec3(1, 0, 0);
    Vec3 n = make_bsdf(m, si, textures).frame.n;
    CHECK(n.x == doctest::Approx(s).epsilon(1e-3));
    CHECK(n.z == doctest::Approx(s).epsilon(1e-3));
    m.normal_scale = 0.5f;
    n = make_bsdf(m, si, textures).frame.n;
    CHECK(n.x == doctest::Approx(0.5f * s / std::sqrt(0.25f * 0.5f + 0.5f)).epsilon(1e-3));
    m.normal_scale = 1;
    m.normal_texture = 1;
    CHECK(make_bsdf(m, si, textures).frame.n.y == doctest::Approx(s).epsilon(1e-3));  // +y = cross(n, t)
    si.tangent_sign = -1;  // mirrored UVs: the bitangent turns around
    CHECK(make_bsdf(m, si, textures).frame.n.y == doctest::Approx(-s).epsilon(1e-3));
}

TEST_CASE("pbr inputs: generated tangents follow u and flip their sign on mirrored UVs") {
    TriangleMesh mesh = square();
    auto t = generate_tangents(mesh);
    REQUIRE(t.size() == 4);
    for (const auto& v : t) {
        CHECK(v[0] == doctest::Approx(1.0f));
        CHECK(v[3] == 1.0f);
    }
    for (Vec2& uv : mesh.uvs) uv.x = 1 - uv.x;  // mirrored in u
    t = generate_tangents(mesh);
    for (const auto& v : t) {
        CHECK(v[0] == doctest::Approx(-1.0f));
        CHECK(v[3] == -1.0f);
    }
    mesh.uvs.clear();
    CHECK(generate_tangents(mesh).empty());
}

TEST_CASE("pbr inputs: a normal-mapped or anisotropic mesh without tangents gets them at scene build") {
    for (const bool normal_mapped : {true, false}) {
        SceneDesc d = empty_scene(Rgb(0.0f));
        MaterialDesc m = white_pbr();
        if (normal_mapped) {
            m.normal_texture = 0;
            d.textures.push_back(strip({Rgb(0.5f, 0.5f, 1.0f)}));
        } else {
            m.anisotropy = 0.5f;
        }
        d.materials.push_back(m);
        d.meshes.push_back(square());
        const Scene scene = build_scene(d);
        CAPTURE(normal_mapped);
        REQUIRE(scene.triangles.tangents.size() == 4);
        Ray ray{{0.5f, 0.5f, 1}, {0, 0, -1}, 0.0f, kInfinity, 0.0f};
        Hit hit;
        REQUIRE(scene.intersect(ray, hit));
        CHECK(scene.interact(ray, hit).tangent.x == doctest::Approx(1.0f));
    }
}

TEST_CASE("pbr inputs: one-sided materials are invisible from behind, for hits and shadows") {
    SceneDesc d = empty_scene(Rgb(0.0f));
    MaterialDesc m = white_pbr();
    m.double_sided = false;
    d.materials.push_back(m);
    d.meshes.push_back(square());
    const Scene scene = build_scene(d);
    Hit hit;
    Ray from_front{{0.5f, 0.5f, 1}, {0, 0, -1}, 0.0f, kInfinity, 0.0f};
    CHECK(scene.intersect(from_front, hit));
    Ray from_back{{0.5f, 0.5f, -1}, {0, 0, 1}, 0.0f, kInfinity, 0.0f};
    CHECK(!scene.intersect(from_back, hit));
    CHECK(!scene.occluded(Ray{{0.5f, 0.5f, -1}, {0, 0, 1}, 0.0f, 5.0f, 0.0f}));
    CHECK(scene.occluded(Ray{{0.5f, 0.5f, 1}, {0, 0, -1}, 0.0f, 5.0f, 0.0f}));
}

TEST_CASE("pbr inputs: emission adds to what the surface reflects") {
    MaterialDesc m = white_pbr();
    m.radiance.color = Rgb(0.5f, 1.0f, 2.0f);
    for (float sky : {0.0f, 1.0f}) {
        SceneDesc d = empty_scene(Rgb(sky));
        d.materials.push_back(m);
        d.spheres.push_back({{0, 0, 0}, 1.0f, 1, {0, 0, 0}});
        const Scene scene = build_scene(d);
        const Stat s =
            radiance_stats(scene, Ray{{0, -5, 0}, {0, 1, 0}, 0.0f, kInfinity, 0.0f}, scaled(2000), 8);
        // White, non-metal: it reflects all of a uniform sky (furnace), plus its glow.
        CHECK(within(s, m.radiance.color + Rgb(sky), 4, 0.01f));
    }
}

TEST_CASE(
    "pbr inputs: the anisotropy texture gives the direction in the tangent frame and scales the strength") {
    // RG (0.5, 1): the direction (0, 1), the bitangent; B 0.5 halves the strength.
    const std::vector<TextureDesc> textures = {strip({Rgb(0.5f, 1.0f, 0.5f)})};
    MaterialDesc m = white_pbr();
    m.roughness = 0.5f;
    m.anisotropy = 0.8f;
    m.anisotropy_texture = 0;
    SurfaceInteraction si = flat_hit();
    si.tangent = Vec3(1, 0, 0);
    Bsdf b = make_bsdf(m, si, textures);
    REQUIRE(b.anisotropic);
    CHECK(dot(b.frame.s, Vec3(0, 1, 0)) == doctest::Approx(1.0f));
    CHECK(b.alpha_y == doctest::Approx(0.25f));
    CHECK(b.alpha == doctest::Approx(0.25f + 0.75f * 0.4f * 0.4f));
    m.anisotropy_rotation = 0.5f * kPi;  // turns the bitangent to -tangent
    b = make_bsdf(m, si, textures);
    CHECK(dot(b.frame.s, Vec3(-1, 0, 0)) == doctest::Approx(1.0f));
}
