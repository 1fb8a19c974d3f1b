// KHR_materials_volume attenuation: light travelling inside a transmissive pbr
// volume decays by Beer-Lambert, to attenuation_color after attenuation_distance.
#include <doctest/doctest.h>

#include "mesh_fixtures.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Clear glass (ior 1.5, nearly smooth) whose volume decays to `color` over `distance`.
MaterialDesc tinted_glass(Rgb color, float distance) {
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.albedo.color = Rgb(1.0f);
    m.metallic = 0;
    m.roughness = 0.05f;
    m.transmission = 1;
    m.ior = 1.5f;
    m.attenuation_color = color;
    m.attenuation_distance = distance;
    return m;
}

/// Radiance straight down through the slab under a white sky (a furnace without absorption).
Stat through_slab(float thickness, const MaterialDesc& glass) {
    SceneDesc d = empty_scene(Rgb(1.0f));
    d.materials.push_back(glass);
    d.meshes.push_back(make_slab(5.0f, thickness));
    const Scene scene = build_scene(d);
    return radiance_stats(scene, Ray{{0.1f, 0.2f, 3.0f}, {0, 0, -1}, 0.0f, kInfinity, 0.0f}, scaled(4000),
                          16);
}

/// At normal incidence with reflectance r = 0.04 per face and transmittance T per
/// crossing, under a white sky on both sides: r from the top face, and (1 - r)^2 T / (1 - r T)
/// out of either face after 1, 3, 5, ... crossings (T = 1: a furnace, exactly 1).
Rgb expected(Rgb transmittance) {
    const float r = 0.04f;
    Rgb out;
    for (int c = 0; c < 3; ++c)
        out[c] = r + (1.0f - r) * (1.0f - r) * transmittance[c] / (1.0f - r * transmittance[c]);
    return out;
}

}  // namespace

TEST_CASE("pbr volume: Beer-Lambert attenuation through a slab grows exponentially with thickness") {
    const Rgb color(0.25f, 0.5f, 1.0f);
    const Stat one = through_slab(1.0f, tinted_glass(color, 1.0f));
    CHECK(within(one, expected(color), 4, 0.01f));
    const Stat two = through_slab(2.0f, tinted_glass(color, 1.0f));
    CHECK(within(two, expected(color * color), 4, 0.01f));
    // Half the distance per decay: the same as twice the thickness.
    const Stat half = through_slab(1.0f, tinted_glass(color, 0.5f));
    CHECK(agree(half, two, 4));
    // Without attenuation the slab is a furnace: everything comes back white.
    const Stat clear = through_slab(1.0f, tinted_glass(Rgb(1.0f), kInfinity));
    CHECK(within(clear, Rgb(1.0f), 4, 0.01f));
}
