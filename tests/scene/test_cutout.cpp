// Cut-out (alpha-tested) triangles: the any-hit filter of scene/alpha_filter.h
// as seen by shadow rays, camera rays, the loaders and the BVH layouts.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

#include "scene/accelerator.h"
#include "io/image_io.h"
#include "mesh_fixtures.h"
#include "render/features.h"
#include "scene/scene.h"
#include "io/scene_parser.h"
#include "io/gltf_test_doc.h"

using namespace sahara;
using namespace sahara::test;
namespace fs = std::filesystem;

namespace {

constexpr int kChecker = 8;  ///< checker texels per side; one texel per square

/// Alpha of checker square (column, row), row 0 at the image top: the top-left square is opaque.
float checker_alpha(int col, int row) { return ((col + row) & 1) ? 0.0f : 1.0f; }

/// Whether the checker is transparent at (u, v) (v = 0 at the image bottom, as in SceneDesc).
bool checker_transparent(float u, float v) {
    const int col = std::clamp(int(std::floor(u * kChecker)), 0, kChecker - 1);
    const int row = std::clamp(int(std::floor((1.0f - v) * kChecker)), 0, kChecker - 1);
    return checker_alpha(col, row) == 0.0f;
}

/// The checker as a texture: white, alpha 0 or 1 per texel.
TextureDesc checker_texture() {
    auto img = std::make_shared<Image>();
    img->width = img->height = kChecker;
    for (int row = 0; row < kChecker; ++row)
        for (int col = 0; col < kChecker; ++col)
            img->rgba.insert(img->rgba.end(), {1.0f, 1.0f, 1.0f, checker_alpha(col, row)});
    TextureDesc t;
    t.path = "checker";
    t.image = img;
    t.wrap_u = t.wrap_v = WrapMode::clamp;
    return t;
}

/// Material 1: the checker cut-out (MASK at 0.5 when `mask`, else stochastic).
SceneDesc checker_scene(bool mask) {
    SceneDesc d;
    d.materials.push_back(default_material());
    MaterialDesc m = default_material();
    m.name = "checker";
    m.alpha_texture = 0;
    if (mask) m.alpha_cutoff = 0.5f;
    d.materials.push_back(m);
    d.textures.push_back(checker_texture());
    d.meshes.push_back(unit_grid(6, 0.0f, 1));
    return d;
}

/// Uniform points on the unit square (fixed seed).
std::vector<Vec2> uniform_points(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Vec2> p(static_cast<size_t>(n));
    for (Vec2& q : p) q = {u(rng), u(rng)};
    return p;
}

/// A ray from `from` through the quad point (x, y, 0), ending at twice that distance.
Ray ray_through(Vec3 from, Vec2 q) {
    Ray r;
    r.origin = from;
    r.dir = Vec3(q.x, q.y, 0.0f) - from;
    r.tmin = 1e-4f;
    r.tmax = 2.0f;
    return r;
}

/// Whether the point lies within `eps` of a checker square's edge (either answer is right there).
bool near_square_edge(Vec2 q, float eps) {
    const auto near = [eps](float x) {
        const float f = x * kChecker;
        return std::abs(f - std::round(f)) < eps * kChecker;
    };
    return near(q.x) || near(q.y);
}

/// Centres of the checker squares.
std::vector<Vec2> square_centres() {
    std::vector<Vec2> c;
    for (int j = 0; j < kChecker; ++j)
        for (int i = 0; i < kChecker; ++i)
            c.push_back({(float(i) + 0.5f) / kChecker, (float(j) + 0.5f) / kChecker});
    return c;
}

/// Restores automatic SIMD path selection when a test ends.
struct SimdGuard {
    ~SimdGuard() { force_simd_path(best_simd_path()); }
};

std::vector<SimdPath> simd_paths() { return runnable_simd_paths(); }

constexpr BvhLayout kLayouts[] = {BvhLayout::wide8, BvhLayout::pairs};

/// Runs `check(acc)` on an Accelerator of `scene` in each layout on each SIMD path
/// this CPU runs, with the layout and path named in failure messages.
template <class Check>
void for_each_layout_and_path(const Scene& scene, Check&& check) {
    SimdGuard guard;
    for (BvhLayout layout : kLayouts)
        for (SimdPath path : simd_paths()) {
            force_simd_path(path);
            AcceleratorOptions opt;
            opt.layout = layout;
            const Accelerator acc(scene, opt);
            INFO("layout ", std::string(bvh_layout_name(layout)), " path ",
                 std::string(simd_path_name(path)));
            check(acc);
        }
}

/// 4 standard deviations of a binomial fraction with probability p over n trials.
double four_sigma(double p, int n) { return 4.0 * std::sqrt(p * (1.0 - p) / double(n)); }

}  // namespace

TEST_CASE("cut-outs: shadow rays pass exactly the transparent checker squares") {
    const Scene scene = build_scene(checker_scene(true));
    REQUIRE(scene.accelerator()->has_cutouts());
    CHECK(scene.accelerator()->alpha_filter().size() == scene.triangles.size());
    const Vec3 point(0.5f, 0.5f, -1.0f);
    const int n = 20000 / kSanitizerDivisor;
    const std::vector<Vec2> pts = uniform_points(n, 7);
    for_each_layout_and_path(scene, [&](const Accelerator& acc) {
        for (Vec2 c : square_centres())
            CHECK(acc.occluded(ray_through(point, c)) != checker_transparent(c.x, c.y));
        int through = 0, wrong = 0;
        for (Vec2 q : pts) {
            const bool open = !acc.occluded(ray_through(point, q));
            through += open ? 1 : 0;
            if (open != checker_transparent(q.x, q.y) && !near_square_edge(q, 1e-4f)) ++wrong;
        }
        CHECK(wrong == 0);
        // Half the area is transparent.
        CHECK(std::abs(double(through) / n - 0.5) < four_sigma(0.5, n));
    });
    // The Scene's own query (the renderer's shadow rays) too.
    int through = 0;
    for (Vec2 q : pts) through += scene.occluded(ray_through(point, q)) ? 0 : 1;
    CHECK(std::abs(double(through) / n - 0.5) < four_sigma(0.5, n));
}

TEST_CASE("cut-outs: camera rays reach the background through the transparent squares") {
    SceneDesc d = checker_scene(true);
    TriangleMesh back = unit_grid(3, -1.0f, 0);  // opaque background one unit below, 3x as wide
    for (Vec3& p : back.positions) p = {3.0f * p.x - 1.0f, 3.0f * p.y - 1.0f, p.z};
    d.meshes.push_back(back);
    const Scene scene = build_scene(d);
    const size_t quad_tris = d.meshes[0].triangle_count();
    const Vec3 eye(0.5f, 0.5f, 2.0f);
    const int n = 20000 / kSanitizerDivisor;
    for_each_layout_and_path(scene, [&](const Accelerator& acc) {
        int background = 0, wrong = 0;
        for (Vec2 q : uniform_points(n, 11)) {
            Ray r = ray_through(eye, q);
            Hit h;
            REQUIRE(acc.intersect(r, h));
            const bool behind = prim_index(h.prim) >= quad_tris;
            // The quad is at t = 1, the background at t = 1.5 (in units of the direction).
            CHECK(std::abs(h.t - (behind ? 1.5f : 1.0f)) < 1e-4f);
            background += behind ? 1 : 0;
            if (behind != checker_transparent(q.x, q.y) && !near_square_edge(q, 1e-4f)) ++wrong;
        }
        CHECK(wrong == 0);
        CHECK(std::abs(double(background) / n - 0.5) < four_sigma(0.5, n));
    });
}

TEST_CASE("cut-outs: constant alpha 0.3 blends stochastically and reproducibly") {
    SceneDesc d = checker_scene(false);
    d.materials[1].alpha_texture = -1;
    d.materials[1].alpha = 0.3f;
    const Scene scene = build_scene(d);
    REQUIRE(scene.accelerator()->has_cutouts());
    const int n = 40000 / kSanitizerDivisor;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int occluded = 0, mismatched = 0;
    for (Vec2 q : uniform_points(n, 5)) {
        // Varied origins below the quad, as a lit surface's shadow rays would have.
        const Ray r = ray_through({0.5f + u(rng), 0.5f + u(rng), -1.0f}, q);
        const bool occ = scene.occluded(r);
        occluded += occ ? 1 : 0;
        Ray r2 = r;
        Hit h;
        // Same ray, same answer: again, and from the closest-hit query.
        if (scene.occluded(r) != occ || scene.intersect(r2, h) != occ) ++mismatched;
    }
    CHECK(mismatched == 0);
    CHECK(std::abs(double(occluded) / n - 0.3) < four_sigma(0.3, n));
    // The coin itself is uniform: its mean is 1/2.
    double sum = 0;
    for (uint32_t i = 0; i < 4096; ++i) sum += double(cutout_hash(Ray{{0, 0, 0}, {1, float(i), 2}}, i));
    CHECK(std::abs(sum / 4096 - 0.5) < 0.02);
}

TEST_CASE("cut-outs: a checker alpha texture without cutoff is see-through where alpha is 0") {
    const Scene scene = build_scene(checker_scene(false));
    for (Vec2 c : square_centres())
        CHECK(scene.occluded(ray_through({0.3f, 0.6f, -1.0f}, c)) != checker_transparent(c.x, c.y));
}

TEST_CASE("cut-outs: scenes without them run the plain traversal") {
    SceneDesc d = checker_scene(true);
    d.materials[1].alpha_texture = -1;  // alpha 1, no texture: opaque
    const Scene scene = build_scene(d);
    CHECK_FALSE(scene.accelerator()->has_cutouts());
    CHECK(describe_features(scene).find("cut-outs") == std::string::npos);
    const Scene cut = build_scene(checker_scene(true));
    CHECK(describe_features(cut).find("cut-outs") != std::string::npos);
    for (Vec2 c : square_centres()) CHECK(scene.occluded(ray_through({0.5f, 0.5f, -1.0f}, c)));
}

namespace {

/// Writes a kChecker x kChecker PNG of the checker: RGBA (alpha = checker) or grey (grey = alpha).
void write_checker_png(const fs::path& file, bool rgba) {
    const int channels = rgba ? 4 : 1;
    std::vector<uint8_t> px;
    for (int row = 0; row < kChecker; ++row)
        for (int col = 0; col < kChecker; ++col) {
            const auto a = uint8_t(checker_alpha(col, row) * 255.0f);
            if (rgba)
                px.insert(px.end(), {200, 60, 40, a});
            else
                px.push_back(a);
        }
    write_image_u8(file, kChecker, kChecker, channels, px.data());
}

/// A glTF unit quad in z = 0 (external .bin), alphaMode MASK over an RGBA checker.
void write_gltf_quad(const fs::path& dir) {
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};  // glTF v runs down the image
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    std::ofstream bin(dir / "quad.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(pos), sizeof pos);
    bin.write(reinterpret_cast<const char*>(uv), sizeof uv);
    bin.write(reinterpret_cast<const char*>(idx), sizeof idx);
    bin.close();
    std::ofstream(dir / "quad.gltf")
        << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
 "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "alphaMode": "MASK", "alphaCutoff": 0.5}],
 "textures": [{"source": 0}], "images": [{"uri": "checker_rgba.png"}],
 "buffers": [{"uri": "quad.bin", "byteLength": 92}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                 {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
               {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
               {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
}

/// An OBJ unit quad in z = 0 whose MTL cuts it out with map_d (a grey checker).
void write_obj_quad(const fs::path& dir) {
    std::ofstream(dir / "quad.mtl") << "newmtl leaf\nKd 0.2 0.6 0.2\nmap_d checker_grey.png\n";
    std::ofstream(dir / "quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl leaf\nf 1/1 2/2 3/3 4/4\n";
}

}  // namespace

TEST_CASE("cut-outs: glTF alphaMode MASK and OBJ map_d load see-through") {
    const fs::path dir = fs::temp_directory_path() / ("sahara_cutout_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    write_checker_png(dir / "checker_rgba.png", true);
    write_checker_png(dir / "checker_grey.png", false);
    write_gltf_quad(dir);
    write_obj_quad(dir);
    for (const char* model : {"quad.gltf", "quad.obj"}) {
        INFO(model);
        std::ofstream(dir / "scene.json")
            << R"({"format": "scene/1", "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0]},
 "objects": [{"type": "mesh", "file": ")"
            << model << "\"}]}";
        const Scene scene = build_scene(parse_scene_file(dir / "scene.json"));
        REQUIRE(scene.accelerator()->has_cutouts());
        int open = 0;
        for (Vec2 c : square_centres()) {
            // From the front: the glTF material is single-sided (doubleSided defaults to false).
            const bool through = !scene.occluded(ray_through({0.5f, 0.5f, 1.0f}, c));
            CHECK(through == checker_transparent(c.x, c.y));
            open += through ? 1 : 0;
        }
        CHECK(open == kChecker * kChecker / 2);
    }
    fs::remove_all(dir);
}

TEST_CASE("cut-outs: BVH layouts agree with brute force with the filter on") {
    // Stacked checker layers (MASK and stochastic), a half-transparent sheet and an opaque sphere.
    SceneDesc d = checker_scene(true);
    MaterialDesc blend = d.materials[1];
    blend.alpha_cutoff.reset();
    d.materials.push_back(blend);  // 2: stochastic checker
    MaterialDesc sheet = default_material();
    sheet.alpha = 0.5f;
    d.materials.push_back(sheet);  // 3: constant alpha
    for (int layer = 1; layer < 6; ++layer) {
        TriangleMesh g = unit_grid(5 + layer, 0.2f * float(layer), uint32_t(1 + layer % 3));
        for (Vec3& p : g.positions) p.x += 0.05f * float(layer);
        d.meshes.push_back(g);
    }
    d.meshes.push_back(make_icosphere(2, 0.3f, {0.5f, 0.5f, 0.5f}));
    const Scene scene = build_scene(d);
    const std::vector<Ray> rays = make_random_rays(scene.bounds(), 4000 / kSanitizerDivisor, 21);
    // The same geometry, every material opaque: the filter must change many answers.
    SceneDesc opaque_desc = d;
    for (MaterialDesc& m : opaque_desc.materials) m = default_material();
    const Scene opaque = build_scene(opaque_desc);
    REQUIRE_FALSE(opaque.accelerator()->has_cutouts());
    int changed = 0, hits = 0;
    for (const Ray& r0 : rays) {
        Ray a = r0, b = r0;
        Hit ha, hb;
        const bool fa = scene.accelerator()->intersect(a, ha), fb = opaque.accelerator()->intersect(b, hb);
        hits += fb ? 1 : 0;
        changed += fa != fb || ha.prim != hb.prim ? 1 : 0;
    }
    CHECK(changed > hits / 5);
    for_each_layout_and_path(scene, [&](const Accelerator& acc) {
        REQUIRE(acc.has_cutouts());
        int bad = 0;
        for (const Ray& r0 : rays) {
            Ray a = r0, b = r0;
            Hit ha, hb;
            const bool fa = acc.intersect(a, ha), fb = acc.intersect_brute_force(b, hb);
            if (fa != fb || acc.occluded(r0) != fb || (fa && (ha.t != hb.t || ha.prim != hb.prim))) ++bad;
        }
        CHECK(bad == 0);
    });
}

namespace {

/// A scene holding a glTF unit quad in z = 0 whose COLOR_0 alphas are `alphas`
/// (corners (0,0), (1,0), (1,1), (0,1)), with a double-sided material of `mode`.
Scene vertex_alpha_quad(const fs::path& dir, const char* mode, const std::vector<float>& alphas) {
    gltf::Doc d;
    const int pos = d.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    const int idx = d.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR", 6);
    std::vector<float> rgba;
    for (float a : alphas) rgba.insert(rgba.end(), {0.8f, 0.8f, 0.8f, a});
    const int colors = d.accessor(rgba, 5126, "VEC4", 4);
    const int mesh = d.mesh(pos, idx, 4, {{"COLOR_0", colors}});
    d.j["meshes"][size_t(mesh)]["primitives"][0]["material"] = 0;
    d.j["materials"] = {{{"alphaMode", mode}, {"doubleSided", true}}};
    d.node({{"mesh", mesh}});
    d.write(dir / "quad.gltf");
    std::ofstream(dir / "scene.json")
        << R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0]},
 "objects": [{"type": "mesh", "file": "quad.gltf"}]})";
    return build_scene(parse_scene_file(dir / "scene.json"));
}

}  // namespace

TEST_CASE("cut-outs: glTF COLOR_0 alpha scales MASK and BLEND alpha and OPAQUE ignores it") {
    const fs::path dir = gltf::scratch("vertex_alpha");
    // Alpha 0 along x = 0 and 1 along x = 1: a MASK at 0.5 is open on the left half.
    const Scene mask = vertex_alpha_quad(dir, "MASK", {0, 1, 1, 0});
    REQUIRE(mask.accelerator()->has_cutouts());
    CHECK(mask.materials.at(mask.triangles.material[0]).vertex_alpha);
    for (int i = 1; i < 20; ++i) {
        const float x = float(i) / 20.0f;
        if (std::abs(x - 0.5f) < 1e-3f) continue;
        INFO("x = " << x);
        CHECK(mask.occluded(ray_through({x, 0.5f, 1.0f}, {x, 0.5f})) == (x > 0.5f));
    }

    // Alpha 0.3 everywhere, blended: about 30% of varied rays are stopped.
    const Scene blend = vertex_alpha_quad(dir, "BLEND", {0.3f, 0.3f, 0.3f, 0.3f});
    const int n = 20000 / kSanitizerDivisor;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int occluded = 0;
    for (Vec2 q : uniform_points(n, 13))
        occluded += blend.occluded(ray_through({0.5f + u(rng), 0.5f + u(rng), 1.0f}, q)) ? 1 : 0;
    CHECK(std::abs(double(occluded) / n - 0.3) < four_sigma(0.3, n));

    // OPAQUE: glTF ignores alpha, so the quad stops every ray.
    const Scene opaque = vertex_alpha_quad(dir, "OPAQUE", {0, 0, 0, 0});
    CHECK_FALSE(opaque.materials.at(opaque.triangles.material[0]).vertex_alpha);
    CHECK_FALSE(opaque.accelerator()->has_cutouts());
    for (Vec2 c : square_centres()) CHECK(opaque.occluded(ray_through({0.5f, 0.5f, 1.0f}, c)));
    fs::remove_all(dir);
}

TEST_CASE("cut-outs: the shadow cache keeps the alpha test") {
    const Scene scene = build_scene(checker_scene(true));
    const Accelerator accel(scene);
    REQUIRE(accel.has_cutouts());
    SimdGuard guard;
    for (SimdPath path : simd_paths()) {
        force_simd_path(path);
        OcclusionCache cache;
        int wrong = 0, blocked = 0;
        // Straight down through the square centres in row order: opaque and transparent
        // squares alternate, often within one cached block.
        for (const Vec2 q : square_centres()) {
            const Ray r{{q.x, q.y, 1.0f}, {0, 0, -1}, 0.0f, 2.0f};
            const bool want = !checker_transparent(q.x, q.y);
            wrong += int(accel.occluded(r, cache) != want) + int(accel.occluded(r) != want);
            blocked += int(want);
        }
        CHECK(wrong == 0);
        CHECK(blocked == kChecker * kChecker / 2);
    }
}
