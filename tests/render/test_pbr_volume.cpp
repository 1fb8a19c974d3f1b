// KHR_materials_volume attenuation: light travelling inside a transmissive pbr
// volume decays by Beer-Lambert, to attenuation_color after attenuation_distance.
#include <doctest/doctest.h>

#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// A closed box [-5, 5]^2 x [0, thickness] with outward (counter-clockwise) faces, material 1.
TriangleMesh slab(float thickness) {
    TriangleMesh m;
    m.material = 1;
    const float a = -5.0f, b = 5.0f;
    const Vec3 X(b - a, 0, 0), Y(0, b - a, 0), Z(0, 0, thickness);
    // Each face: a corner and two edges whose cross product points outwards.
    const Vec3 faces[6][3] = {{{a, a, thickness}, X, Y}, {{a, a, 0}, Y, X}, {{b, a, 0}, Y, Z},
                              {{a, a, 0}, Z, Y},         {{a, b, 0}, Z, X}, {{a, a, 0}, X, Z}};
    for (const auto& f : faces) {
        const auto base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {f[0], f[0] + f[1], f[0] + f[1] + f[2], f[0] + f[2]});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

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
    d.meshes.push_back(slab(thickness));
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
