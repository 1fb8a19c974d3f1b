#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "io/model_loader.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;
namespace fs = std::filesystem;

namespace {

/// A unit quad in z = 0 facing +z, written as an OBJ with `colour` on every
/// `v` line (none when empty), loaded as the scene's only mesh under a white
/// sky with `material`.
SceneDesc quad_scene(const std::string& colour, const MaterialDesc& material) {
    // One file per test process: ctest runs test cases in parallel.
    const fs::path dir = fs::temp_directory_path() / "sahara_render_vertex_colours";
    fs::create_directories(dir);
    const fs::path file = dir / ("quad_" + std::to_string(::getpid()) + ".obj");
    std::ofstream(file, std::ios::binary) << "v 0 0 0 " << colour << "\nv 1 0 0 " << colour << "\nv 1 1 0 "
                                          << colour << "\nv 0 1 0 " << colour << "\nf 1 2 3 4\n";
    LoadedModel model = load_obj(file);
    fs::remove(file);
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials = {material};
    for (TriangleMesh& mesh : model.meshes) {
        mesh.material = 0;
        d.meshes.push_back(std::move(mesh));
    }
    return d;
}

/// Mean radiance seen straight down onto the quad's centre.
Rgb seen(SceneDesc d, IntegratorType integrator) {
    d.render.integrator = integrator;
    const Scene scene = build_scene(d);
    return sample_stats(scaled(400), 1,
                        [&](Sampler& s) {
                            return estimate_radiance(
                                scene, Ray{{0.5f, 0.4f, 1}, {0, 0, -1}, 0.0f, kInfinity, 0.0f}, s, 4);
                        })
        .mean;
}

}  // namespace

TEST_CASE("a red-vertex-coloured lambertian quad under a white sky renders red and grey without colours") {
    const MaterialDesc grey = lambertian(Rgb(0.5f));
    // Under a uniform sky of radiance 1 an open Lambertian quad reflects exactly its albedo.
    for (IntegratorType integrator :
         {IntegratorType::path, IntegratorType::whitted, IntegratorType::albedo}) {
        CAPTURE(int(integrator));
        const Rgb red = seen(quad_scene("1 0 0", grey), integrator);
        CHECK(red.x == doctest::Approx(0.5f).epsilon(0.05));
        CHECK(red.y == doctest::Approx(0.0f));
        CHECK(red.z == doctest::Approx(0.0f));
        const Rgb plain = seen(quad_scene("", grey), integrator);
        CHECK(plain.x == doctest::Approx(0.5f).epsilon(0.05));
        CHECK(plain.y == doctest::Approx(0.5f).epsilon(0.05));
        CHECK(plain.z == doctest::Approx(0.5f).epsilon(0.05));
    }
}

TEST_CASE("vertex colours tint a metal's reflectance") {
    const Rgb c = seen(quad_scene("0 1 0", metal(Rgb(1.0f), 0.0f)), IntegratorType::path);
    CHECK(c.x == doctest::Approx(0.0f));
    CHECK(c.y > 0.9f);
    CHECK(c.z == doctest::Approx(0.0f));
}
