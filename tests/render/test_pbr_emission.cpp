// Glowing pbr surfaces (glTF emissiveFactor) are area lights: light sampling
// picks them as it picks emissive materials, and MIS weighs what BSDF sampling finds.
#include <doctest/doctest.h>

#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A Lambertian floor z = 0 (material 1) under a black sky, lit only by a small
/// quad at height 1 facing down with material `lamp` (material 2).
SceneDesc panel_scene(const MaterialDesc& lamp) {
    SceneDesc d = empty_scene(Rgb(0.0f));
    d.materials.push_back(lambertian(Rgb(0.5f)));
    d.materials.push_back(lamp);
    d.planes.push_back({{0, 0, 0}, {0, 0, 1}, 1});
    TriangleMesh m;
    // Counter-clockwise seen from below: the front faces the floor.
    m.positions = {{-0.15f, -0.15f, 1}, {0.15f, 0.15f, 1}, {0.15f, -0.15f, 1}, {-0.15f, 0.15f, 1}};
    m.indices = {0, 1, 2, 0, 3, 1};
    m.material = 2;
    d.meshes.push_back(m);
    return d;
}

/// A pbr material that reflects nothing (black base, ior 1: no specular layer) and glows.
MaterialDesc glowing_pbr(Rgb radiance) {
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = Rgb(0.0f);
    m.metallic = 0;
    m.roughness = 0.5f;
    m.ior = 1.0f;
    m.radiance.color = radiance;
    return m;
}

}  // namespace

TEST_CASE("pbr emission: a glowing pbr quad lights the scene like an emissive quad of equal radiance") {
    const Scene pbr = build_scene(panel_scene(glowing_pbr(Rgb(20.0f, 10.0f, 5.0f))));
    const Scene emissive_lamp = build_scene(panel_scene(emissive(Rgb(20.0f, 10.0f, 5.0f))));
    // Both quads are sampled lights.
    CHECK(pbr.emitters.size() == 2);
    CHECK(emissive_lamp.emitters.size() == 2);
    const Ray ray{{1.0f, -1.0f, 0.8f}, normalize(Vec3(-0.8f, 0.9f, -0.8f)), 0.0f, kInfinity, 0.0f};
    const int n = scaled(6000);
    const Stat a = radiance_stats(pbr, ray, n, 4, 3);
    const Stat b = radiance_stats(emissive_lamp, ray, n, 4, 5);
    CHECK(agree(a, b, 4));
    CHECK(a.mean.x > 0.2f);
    // Light sampling, not BSDF sampling alone: the noise is the emissive quad's, no fireflies.
    CHECK(a.se.x < 1.5f * b.se.x);
    // The lamp seen directly (no MIS: a camera ray) has its radiance.
    const Ray up{{0, 0, 0.5f}, {0, 0, 1}, 0.0f, kInfinity, 0.0f};
    CHECK(within(radiance_stats(pbr, up, 16, 1), Rgb(20.0f, 10.0f, 5.0f), 1, 1e-4f));
}
