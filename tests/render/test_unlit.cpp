// KHR_materials_unlit: camera rays see the base colour as it is; every other
// ray (bounces, shadow rays, whitted's reflections) passes the surface.
#include <doctest/doctest.h>

#include <fstream>
#include <optional>

#include "io/gltf_test_doc.h"
#include "io/scene_parser.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// A glTF holding a 2 x 2 quad at z = 1 (x, y in [-1, 1], facing +z) with one unlit
/// material of base colour `color`, and misleading fallbacks the loader must not read.
fs::path write_unlit_quad(const fs::path& dir, const Rgb& color) {
    gltf::Doc d;
    const int pos = d.positions({-1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1});
    const int idx = d.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR", 6);
    d.node({{"mesh", d.mesh(pos, idx)}});
    d.j["meshes"][0]["primitives"][0]["material"] = 0;
    d.j["materials"] = {{{"pbrMetallicRoughness",
                          {{"baseColorFactor", {color.x, color.y, color.z, 1}}, {"metallicFactor", 1}}},
                         {"emissiveFactor", {1, 1, 1}},
                         {"doubleSided", true},  // seen from below too: shadow rays come from there
                         {"extensions", {{"KHR_materials_unlit", json::object()}}}}};
    d.j["extensionsUsed"] = {"KHR_materials_unlit"};
    d.j["extensionsRequired"] = {"KHR_materials_unlit"};
    return d.write(dir / "unlit.gltf");
}

/// The same quad from a scene file: an OBJ quad drawn with the file's own unlit material.
SceneDesc scene_file_quad(const Rgb& color) {
    const fs::path dir = gltf::scratch("unlit_scene_file");
    std::ofstream(dir / "quad.obj") << "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 2 3 4\n";
    Json scene = Json::parse(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 1, 5]},
                                 "materials": {"sign": {"type": "unlit"}},
                                 "objects": [{"type": "mesh", "file": "quad.obj", "material": "sign"}]})");
    scene["materials"]["sign"]["color"] = {color.x, color.y, color.z};
    return parse_scene_value(scene, dir / "unlit.json");
}

/// Where the unlit quad comes from: a glTF's KHR_materials_unlit, a scene file's
/// `unlit` material, or nowhere (the scene without it).
enum class Quad { gltf, scene_file, none };

/// A scene with the unlit quad of colour `color` above a floor at z = 0 of `floor`.
SceneDesc quad_over_floor(const Rgb& color, const MaterialDesc& floor, Rgb background,
                          Quad quad = Quad::gltf) {
    SceneDesc d = quad == Quad::scene_file ? scene_file_quad(color) : empty_scene(background);
    d.background = empty_scene(background).background;
    d.materials.push_back(floor);
    d.planes.push_back({Vec3(0, 0, 0), Vec3(0, 0, 1), uint32_t(d.materials.size() - 1)});
    if (quad == Quad::gltf)
        merge_loaded_model(d, load_gltf(write_unlit_quad(gltf::scratch("unlit"), color)), std::nullopt);
    d.render.max_depth = 4;
    return d;
}

/// A camera ray straight down onto the quad's middle.
const Ray kDown{Vec3(0.25f, 0.1f, 5), Vec3(0, 0, -1)};
/// A ray that reaches the floor at (1.5, 0, 0) beside the quad; its mirror
/// reflection and the way from there to (-1.5, 0, 2) both cross the quad.
const Ray kBeside{Vec3(3, 0, 1), normalize(Vec3(-1.5f, 0, -1))};

/// What one ray sees at the scene's own max_depth.
Rgb radiance(const SceneDesc& d, IntegratorType integrator, const Ray& ray) {
    return radiance_along(d, integrator, ray, d.render.max_depth);
}

}  // namespace

TEST_CASE("KHR_materials_unlit loads as an unlit material with the base colour only") {
    const fs::path file = write_unlit_quad(gltf::scratch("unlit_load"), Rgb(0.2f, 0.4f, 0.6f));
    const LoadedModel m = load_gltf(file);  // listed in extensionsRequired: accepted
    REQUIRE(m.materials.size() == 1);
    const MaterialDesc& mat = m.materials[0];
    CHECK(mat.type == MaterialType::unlit);
    CHECK(mat.albedo.color == Rgb(0.2f, 0.4f, 0.6f));
    CHECK(max_component(mat.radiance.color) == 0.0f);  // the emissive fallback is not read
    CHECK(mat.extensions == std::vector<std::string>{"KHR_materials_unlit"});
}

TEST_CASE("An unlit surface shows camera rays exactly its colour whatever the lights") {
    for (Quad quad : {Quad::gltf, Quad::scene_file}) {
        CAPTURE(int(quad));
        const Rgb c(0.2f, 0.4f, 0.6f);
        SceneDesc d = quad_over_floor(c, lambertian(Rgb(0.8f)), Rgb(0.5f), quad);
        CHECK(radiance(d, IntegratorType::path, kDown) == c);
        d.lights.push_back({LightDesc::Type::point, Vec3(0, 0, 3), {}, Rgb(50.0f), {}});
        CHECK(radiance(d, IntegratorType::path, kDown) == c);
        d.spheres.push_back({Vec3(2, 2, 4), 0.3f, uint32_t(d.materials.size()), {}});  // off the camera ray
        d.materials.push_back(emissive(Rgb(20.0f)));
        CHECK(radiance(d, IntegratorType::path, kDown) == c);
        CHECK(radiance(d, IntegratorType::whitted, kDown) == c);
        CHECK(radiance(d, IntegratorType::albedo, kDown) == c);
        const Scene scene = build_scene(d);
        CHECK(std::string(path_kernel_name(scene)) == "path<MIS, all materials, unlit>");
    }
}

TEST_CASE("Unlit surfaces cast no shadow and are not seen in reflections") {
    const Rgb c(1.0f, 0.0f, 0.0f);
    SceneDesc bare = quad_over_floor(c, lambertian(Rgb(0.8f)), Rgb(0.0f), Quad::none);
    bare.lights.push_back({LightDesc::Type::point, Vec3(-1.5f, 0, 2), {}, Rgb(10.0f), {}});
    bare.render.max_depth = 2;  // direct light only: deterministic
    for (Quad quad : {Quad::gltf, Quad::scene_file}) {
        CAPTURE(int(quad));
        // Direct light from a point light through the quad: the same as without it.
        SceneDesc lit = quad_over_floor(c, lambertian(Rgb(0.8f)), Rgb(0.0f), quad);
        lit.lights = bare.lights;
        lit.render.max_depth = 2;
        // (bare runs the Lambertian-only kernel, lit the general one: equal up to rounding)
        const auto same = [](const Rgb& a, const Rgb& b) { return length(a - b) <= 1e-5f * length(b); };
        const Rgb through = radiance(lit, IntegratorType::path, kBeside);
        CHECK(through.x > 0.05f);
        CHECK(same(through, radiance(bare, IntegratorType::path, kBeside)));
        CHECK(same(radiance(lit, IntegratorType::whitted, kBeside),
                   radiance(bare, IntegratorType::whitted, kBeside)));
        // An opaque quad there does shadow the point (the geometry above is right).
        SceneDesc blocked = lit;
        for (MaterialDesc& m : blocked.materials)
            if (m.type == MaterialType::unlit) m.type = MaterialType::lambertian;
        CHECK(radiance(blocked, IntegratorType::path, kBeside) == Rgb(0.0f));

        // A mirror floor reflects the sky behind the quad, not the quad's colour.
        const Rgb sky(0.3f, 0.5f, 0.7f);
        SceneDesc mirror = quad_over_floor(c, metal(Rgb(1.0f), 0.0f), sky, quad);
        for (IntegratorType t : {IntegratorType::path, IntegratorType::whitted}) {
            const Rgb seen = radiance(mirror, t, kBeside);
            CHECK(length(seen - sky) < 1e-5f);
        }
    }
}

TEST_CASE("An unlit surface adds no energy to a white furnace and takes none from it") {
    // A white Lambertian floor under a uniform sky of 1 returns exactly 1 on every
    // path; an unlit quad of any colour above it changes nothing, for every kernel.
    for (const Rgb& c : {Rgb(0.0f), Rgb(1.0f), Rgb(0.3f, 0.9f, 0.1f)}) {
        SceneDesc d = quad_over_floor(c, lambertian(Rgb(1.0f)), Rgb(1.0f));
        d.render.max_depth = 16;
        const Scene scene = build_scene(d);
        const Stat s = radiance_stats(scene, kBeside, scaled(2000), 16);
        CHECK(within(s, Rgb(1.0f), 0.0f, 1e-5f));
        for (LightStrategy strategy : {LightStrategy::mis, LightStrategy::bsdf_only}) {
            const Stat w = sample_stats(scaled(500), 5, [&](Sampler& sampler) {
                return path_trace_with(scene, kBeside, sampler, 16, strategy);
            });
            CHECK(within(w, Rgb(1.0f), 0.0f, 1e-5f));
        }
    }
}
