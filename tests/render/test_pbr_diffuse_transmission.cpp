// KHR_materials_diffuse_transmission in the pbr BSDF: the material left bit for
// bit without it, energy, reciprocity through the surface, sampling against the
// reported density, and a leaf lit from behind.
#include <doctest/doctest.h>

#include "pbr_test_util.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test;

namespace {

MaterialDesc translucent(MaterialDesc m, float share, Rgb color = Rgb(1.0f)) {
    m.diffuse_transmission = share;
    m.diffuse_transmission_color = color;
    m.thin_walled = true;
    return m;
}

/// A square [-4, 4]^2 in the plane z, facing +z, of material `material`.
TriangleMesh square(float z, uint32_t material) {
    TriangleMesh m;
    m.material = material;
    m.positions = {{-4, -4, z}, {4, -4, z}, {4, 4, z}, {-4, 4, z}};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

}  // namespace

TEST_CASE("diffuse transmission 0 leaves the pbr BSDF bit for bit") {
    for (const MaterialDesc& base : {pbr(Rgb(0.8f, 0.4f, 0.2f), 0.0f, 0.3f), pbr(Rgb(0.6f), 0.5f, 0.05f)}) {
        const Bsdf plain = bsdf_of(base), b = bsdf_of(translucent(base, 0.0f, Rgb(0.2f, 0.9f, 0.1f)));
        for (float cos_o : {0.9f, 0.4f, 0.1f})
            for (float cos_i : {0.95f, 0.5f, -0.3f, -0.8f}) {
                const Vec3 wo = direction(cos_o, 0.2f), wi = direction(cos_i, 1.3f);
                float p0 = 0, p1 = 0;
                CHECK(eval_pbr(plain, wo, wi, &p0) == eval_pbr(b, wo, wi, &p1));
                CHECK(p0 == p1);
                BsdfSample s0, s1;
                const bool ok0 = sample_pbr(plain, wo, Vec2(std::abs(cos_i), 0.3f), cos_o, s0);
                const bool ok1 = sample_pbr(b, wo, Vec2(std::abs(cos_i), 0.3f), cos_o, s1);
                CHECK(ok0 == ok1);
                if (ok0 && ok1) CHECK(s0.weight == s1.weight);
            }
    }
}

TEST_CASE("diffuse transmission takes its share of the diffuse base to the far side") {
    const MaterialDesc base = pbr(Rgb(0.8f), 0.0f, 0.5f);
    const Bsdf opaque = bsdf_of(base), leaf = bsdf_of(translucent(base, 0.6f, Rgb(1.0f, 0.5f, 0.25f)));
    const Vec3 wo = direction(0.8f, 0.0f), below = direction(-0.7f, 2.0f), above = direction(0.7f, 2.0f);
    float p = 0;
    CHECK(eval_pbr(opaque, wo, below, &p) == Rgb(0.0f));
    const Rgb through = eval_pbr(leaf, wo, below, &p);
    CHECK(p > 0);
    // Coloured by its own colour, not the base colour.
    CHECK(through.x == doctest::Approx(2.0f * through.y).epsilon(1e-5));
    CHECK(through.x == doctest::Approx(4.0f * through.z).epsilon(1e-5));
    // The diffuse reflection keeps 0.4 of what it had; the specular lobe is untouched.
    const Rgb r_opaque = eval_pbr(opaque, wo, above, &p), r_leaf = eval_pbr(leaf, wo, above, &p);
    CHECK(r_leaf.x < r_opaque.x);
    // Transmitted and reflected diffuse light share the scaling: 0.6 x 1 against 0.4 x 0.8 of it.
    const Vec3 mirror_below(above.x, above.y, -above.z);
    const Rgb diffuse_lost = r_opaque - r_leaf;
    CHECK(eval_pbr(leaf, wo, mirror_below, &p).x ==
          doctest::Approx(diffuse_lost.x * 0.6f / (0.6f * 0.8f)).epsilon(1e-4));
}

TEST_CASE("white furnace: a white diffusely transmitting pbr material neither gains nor loses") {
    const int n = scaled(20000);
    for (float share : {1.0f, 0.5f})
        for (float roughness : {0.05f, 0.5f, 1.0f})
            for (float transmission : {0.0f, 0.5f}) {
                MaterialDesc m = translucent(pbr(Rgb(1.0f), 0.0f, roughness), share);
                m.transmission = transmission;
                const Bsdf b = bsdf_of(m);
                for (float cos_o : {1.0f, 0.5f, 0.1f}) {
                    const Stat a = directional_albedo(b, direction(cos_o, 0.4f), n);
                    INFO("share " << share << " roughness " << roughness << " transmission " << transmission
                                  << " cos_o " << cos_o << " albedo " << a.mean.x);
                    for (int c = 0; c < 3; ++c) CHECK(a.mean[c] <= 1.0f + 4.0f * a.se[c] + 0.005f);
                    // The diffuse lobes lose nothing (rough thin refraction, single scattering, does).
                    if (transmission == 0.0f) CHECK(a.mean.x > 0.93f);
                }
            }
}

TEST_CASE("diffuse transmission is reciprocal through the surface and samples its pdf") {
    for (const MaterialDesc& m :
         {translucent(pbr(Rgb(0.7f, 0.5f, 0.3f), 0.0f, 0.4f), 0.7f, Rgb(0.9f, 0.6f, 0.2f)),
          translucent(pbr(Rgb(0.9f), 0.3f, 0.3f), 1.0f)}) {
        const Bsdf b = bsdf_of(m);
        for (float c1 : {0.9f, 0.4f})
            for (float c2 : {-0.8f, -0.2f}) {
                // Light from a (above) to b (below), and back from -b (now above) to -a.
                const Vec3 a = direction(c1, 0.3f), bb = direction(c2, 2.1f);
                float p = 0;
                const Rgb fab = eval_pbr(b, a, bb, &p) / std::abs(bb.z), fba = eval_pbr(b, -bb, -a, &p) / a.z;
                for (int k = 0; k < 3; ++k) CHECK(fab[k] == doctest::Approx(fba[k]).epsilon(1e-4));
            }
        for (float cos_o : {0.8f, 0.25f}) {
            const Vec3 wo = direction(cos_o, 1.0f);
            const double z = pbr_chi2_deviate(scaled(200000), b, wo);
            const double integral = pbr_pdf_integral(b, wo), success = pbr_sample_success_rate(b, wo, 100000);
            INFO("roughness " << m.roughness << " cos_o " << cos_o << " deviate " << z << " integral "
                              << integral << " success " << success);
            CHECK(z < 3.5);
            CHECK(integral == doctest::Approx(success).epsilon(0.01));
        }
    }
}

TEST_CASE("a diffusely transmitting leaf lit from behind glows on the far side") {
    // A thin leaf at z = 0 between a camera above and a glowing sheet below, in the dark.
    const auto seen_from_above = [](float share) {
        SceneDesc d = empty_scene(Rgb(0.0f));
        d.materials.push_back(
            translucent(pbr(Rgb(0.3f, 0.8f, 0.2f), 0.0f, 0.6f), share, Rgb(0.9f, 0.9f, 0.3f)));
        d.materials.push_back(emissive(Rgb(1.0f)));
        d.meshes.push_back(square(0.0f, 1));
        d.meshes.push_back(square(-1.0f, 2));
        return radiance_stats(build_scene(d), Ray{{0.2f, 0.1f, 2.0f}, {0, 0, -1}, 0.0f, kInfinity, 0.0f},
                              scaled(4000), 6);
    };
    const Stat opaque = seen_from_above(0.0f), leaf = seen_from_above(1.0f);
    INFO("opaque " << opaque.mean.x << " leaf " << leaf.mean.x << " " << leaf.mean.y << " " << leaf.mean.z);
    CHECK(max_component(opaque.mean) < 1e-6f);
    // Most of the sheet's light comes through, in the transmission colour.
    CHECK(leaf.mean.x > 0.5f);
    CHECK(leaf.mean.z < 0.5f * leaf.mean.x);
}
