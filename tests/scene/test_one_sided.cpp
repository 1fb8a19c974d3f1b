// One-sided triangles (a material with double_sided false, glTF doubleSided false):
// rays pass through their back faces in every traversal (single rays of each
// layout and SIMD path, ray packets, the render command with and without
// packets), and such a scene is not a cut-out scene: it keeps the fast paths.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "accel/packet.h"
#include "accel/simd_path.h"
#include "cli_test_util.h"
#include "mesh_fixtures.h"
#include "io/image_io.h"
#include "render/features.h"
#include "scene/accelerator.h"
#include "scene/scene.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Material 1 one-sided (pbr) at z = 0 facing +z; material 0 (double-sided) at z = 1 behind it.
SceneDesc one_sided_scene(bool double_sided) {
    SceneDesc d;
    d.materials.push_back(MaterialDesc{});
    MaterialDesc m;
    m.type = MaterialType::pbr;
    m.double_sided = double_sided;
    d.materials.push_back(m);
    d.meshes.push_back(unit_grid(8, 0.0f, 1));
    d.meshes.push_back(unit_grid(8, 1.0f, 0));
    return d;
}

/// 16 parallel rays over the grid, from z0 along dz (+1 or -1).
RayPacket packet_along(float z0, float dz) {
    RayPacket p;
    for (int i = 0; i < kPacketSize; ++i)
        p.set(i, Ray{{0.1f + 0.2f * float(i % 4), 0.1f + 0.2f * float(i / 4), z0},
                     {0.0f, 0.0f, dz},
                     0.0f,
                     kInfinity,
                     0.0f});
    return p;
}

}  // namespace

TEST_CASE("one-sided: back faces let rays through in every layout and SIMD path and in packets") {
    const Scene scene = build_scene(one_sided_scene(false));
    for (BvhLayout layout : {BvhLayout::wide8, BvhLayout::pairs}) {
        AcceleratorOptions options;
        options.layout = layout;
        const Accelerator accel(scene, options);
        CHECK_FALSE(accel.has_cutouts());
        CHECK(accel.one_sided_count() == 128);
        for (SimdPath path : runnable_simd_paths()) {
            INFO(std::string(simd_path_name(path)), " layout ", int(layout));
            force_simd_path(path);
            // From the front (above z = 0, looking down): the one-sided grid at t = 0.5.
            RayPacket front = packet_along(0.5f, -1.0f);
            HitPacket hits;
            accel.intersect_packet(front, hits);
            for (int i = 0; i < kPacketSize; ++i) {
                CHECK(hits.t[i] == doctest::Approx(0.5f));
                Ray r = front.ray(i);
                r.tmax = kInfinity;
                Hit h;
                REQUIRE(accel.intersect(r, h));
                CHECK(h.t == doctest::Approx(0.5f));
                CHECK(accel.occluded(Ray{r.origin, r.dir, 0.0f, 1.0f, 0.0f}));
                r.tmax = kInfinity;  // intersect() lowered it to the hit
                REQUIRE(accel.intersect_brute_force(r, h));
                CHECK(h.t == doctest::Approx(0.5f));
            }
            // From behind (below z = 0, looking up): through it, onto the grid at z = 1.
            RayPacket back = packet_along(-0.5f, 1.0f);
            accel.intersect_packet(back, hits);
            for (int i = 0; i < kPacketSize; ++i) {
                CHECK(hits.t[i] == doctest::Approx(1.5f));
                Ray r = back.ray(i);
                r.tmax = kInfinity;
                Hit h;
                REQUIRE(accel.intersect(r, h));
                CHECK(h.t == doctest::Approx(1.5f));
                CHECK_FALSE(accel.occluded(Ray{r.origin, r.dir, 0.0f, 1.0f, 0.0f}));
                r.tmax = kInfinity;
                REQUIRE(accel.intersect_brute_force(r, h));
                CHECK(h.t == doctest::Approx(1.5f));
            }
        }
        clear_forced_simd_path();
    }
}

TEST_CASE("one-sided: not a cut-out scene - packets stay on and info names them apart") {
    const Scene one_sided = build_scene(one_sided_scene(false));
    const Scene two_sided = build_scene(one_sided_scene(true));
    CHECK(one_sided.cutout_triangle_count() == 0);
    CHECK(one_sided.accelerator()->one_sided_count() == 128);
    CHECK(two_sided.accelerator()->one_sided_count() == 0);
    CHECK(one_sided.packets_pay_off() == two_sided.packets_pay_off());
    const std::string f = describe_features(one_sided);
    CHECK(f.find("one-sided (128 triangles") != std::string::npos);
    CHECK(f.find("cut-outs") == std::string::npos);
    CHECK(describe_features(two_sided).find("one-sided") == std::string::npos);
}

namespace {

/// A glTF quad over [-10, 10]^2 at z = 0 facing +z, black, doubleSided false.
void write_one_sided_gltf(const std::filesystem::path& file) {
    std::ofstream(file) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
 "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "doubleSided": false}],
 "buffers": [{"byteLength": 60,
   "uri": "data:application/octet-stream;base64,AAAgwQAAIMEAAAAAAAAgQQAAIMEAAAAAAAAgQQAAIEEAAAAAAAAgwQAAIEEAAAAAAAABAAIAAAACAAMA"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                "min": [-10, -10, 0], "max": [10, 10, 0]},
               {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
}

/// A scene file viewing quad.gltf from height `z` under a white sky.
void write_view(const std::filesystem::path& file, float z) {
    std::ofstream(file) << R"({"format": "scene/1", "camera": {"position": [0, 0, )" << z
                        << R"(], "look_at": [0, 0, 0], "up": [0, 1, 0], "vfov": 40},
 "background": {"type": "constant", "color": [1, 1, 1]},
 "objects": [{"type": "mesh", "file": "quad.gltf"}]})";
}

}  // namespace

TEST_CASE("one-sided: a glTF quad with doubleSided false renders from the front only - packets or not") {
    const TempDir dir("one_sided_gltf");
    write_one_sided_gltf(dir.path / "quad.gltf");
    write_view(dir.path / "front.json", 3.0f);
    write_view(dir.path / "back.json", -3.0f);
    const CliRun info = run_sahara("info quad.gltf", dir);
    REQUIRE(info.code == 0);
    CHECK(info.out.find("one-sided (2 triangles") != std::string::npos);
    CHECK(info.out.find("cut-outs") == std::string::npos);
    // The features line names the material types the file has: pbr only.
    CHECK(info.out.find("materials: pbr (metallic-roughness)") != std::string::npos);
    CHECK(info.out.find("materials: lambertian") == std::string::npos);
    for (const char* packets : {"", " --no-packets"}) {
        for (const char* view : {"front", "back"}) {
            INFO(view, packets);
            const std::string out = std::string(view) + ".pfm";
            const CliRun run = run_sahara(
                std::string("render ") + view + ".json --spp 2 --size 16x12 --seed 1 -o " + out + packets,
                dir);
            REQUIRE(run.code == 0);
            const auto img = read_image(dir.path / out, false);
            REQUIRE(img);
            float lo = 1e9f, hi = -1e9f;
            for (size_t p = 0; p < img->rgba.size(); p += 4) {
                lo = std::min(lo, img->rgba[p]);
                hi = std::max(hi, img->rgba[p]);
            }
            if (std::string(view) == "front") {
                CHECK(hi < 0.5f);  // black: only its 4 % specular reflection of the sky
            } else {
                CHECK(lo == doctest::Approx(1.0f));  // the sky through the quad's back
                CHECK(hi == doctest::Approx(1.0f));
            }
        }
    }
}

TEST_CASE("one-sided: the shadow cache does not let a back face block the next ray") {
    const Scene scene = build_scene(one_sided_scene(false));
    const Accelerator accel(scene);
    for (SimdPath path : runnable_simd_paths()) {
        force_simd_path(path);
        OcclusionCache cache;
        // From between the grids downwards: the one-sided grid's front face blocks the ray
        // and fills the cache with its block.
        REQUIRE(accel.occluded(Ray{{0.3f, 0.3f, 0.5f}, {0, 0, -1}}, cache));
        REQUIRE(cache.owner == &accel);
        // From below upwards through the same block's back face, stopping short of the
        // double-sided grid: nothing blocks it, cached block or not.
        const Ray up{{0.3f, 0.3f, -0.5f}, {0, 0, 1}, 0.0f, 1.2f};
        CHECK_FALSE(accel.occluded(up));
        CHECK_FALSE(accel.occluded(up, cache));
    }
    force_simd_path(best_simd_path());
}
