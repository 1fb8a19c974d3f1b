// EXT_mesh_gpu_instancing: a node's mesh loads once, as a prototype, with one
// instance per entry of its TRANSLATION / ROTATION / SCALE (or custom) accessors; the
// documents are built here, the references with plain nodes or by hand.
#include <cmath>
#include <functional>
#include <limits>

#include "gltf_grid_mesh.h"
#include "io/mesh_triangles.h"
#include "io/scene_parser.h"
#include "io/view_scene.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render_test_util.h"
#include "scene/instances.h"
#include "scene/scene.h"

using namespace sahara;
using namespace sahara::test::gltf;

namespace {

const char* kExt = "EXT_mesh_gpu_instancing";

/// Per-instance transforms of the test grids (rotations by quarter and half turns,
/// so that the instances' boxes are exact and `sahara view` frames both files alike).
struct Placements {
    std::vector<float> t, r, s;
    size_t size() const { return t.size() / 3; }
};

Placements grid_instances(int side) {
    Placements set;
    const float h = std::sqrt(0.5f);
    const std::vector<std::vector<float>> turns = {
        {0, 0, 0, 1}, {0, 0, h, h}, {0, 1, 0, 0}, {h, 0, 0, h}};  // none, z 90, y 180, x 90
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            const size_t k = set.size();
            set.t.insert(set.t.end(), {1.5f * float(x), 0.2f * float(k % 3), -1.5f * float(y)});
            const auto& q = turns[k % turns.size()];
            set.r.insert(set.r.end(), q.begin(), q.end());
            set.s.insert(set.s.end(), {1.0f + 0.25f * float(k % 2), 1.0f, 0.5f + 0.25f * float(k % 3)});
        }
    return set;
}

/// The grid mesh placed by a parent node (translated and scaled); the
/// instanced node also has a child with the same mesh, drawn once.
struct Scenario {
    Doc d;
    int mesh = -1;
};

Scenario grid_scenario() {
    Scenario sc;
    const GridMesh g = grid_mesh(3);
    const int pos = sc.d.positions(g.positions);
    const int nrm = sc.d.accessor(g.normals, 5126, "VEC3", g.vertices());
    const int idx = sc.d.accessor(g.indices, 5125, "SCALAR", g.indices.size());
    sc.mesh = sc.d.mesh(pos, idx, 4, {{"NORMAL", nrm}});
    return sc;
}

/// EXT_mesh_gpu_instancing on a child of a moved parent, with a child of its own.
fs::path write_instanced(const fs::path& file, const Placements& set) {
    Scenario sc = grid_scenario();
    Doc& d = sc.d;
    const size_t n = set.size();
    json attrs = {{"TRANSLATION", d.accessor(set.t, 5126, "VEC3", n)},
                  {"ROTATION", d.accessor(set.r, 5126, "VEC4", n)},
                  {"SCALE", d.accessor(set.s, 5126, "VEC3", n)}};
    const int child = d.node({{"mesh", sc.mesh}, {"translation", {0, 3, 0}}}, false);
    const int instanced = d.node(
        {{"mesh", sc.mesh}, {"children", {child}}, {"extensions", {{kExt, {{"attributes", attrs}}}}}}, false);
    d.node({{"translation", {1, -2, 0.5}}, {"scale", {2, 2, 2}}, {"children", {instanced}}});
    d.j["extensionsUsed"] = {kExt};
    return d.write(file);
}

/// The same scene as write_instanced with one plain node per instance.
fs::path write_separate(const fs::path& file, const Placements& set) {
    Scenario sc = grid_scenario();
    Doc& d = sc.d;
    json children = json::array();
    for (size_t k = 0; k < set.size(); ++k)
        children.push_back(
            d.node({{"mesh", sc.mesh},
                    {"translation", {set.t[3 * k], set.t[3 * k + 1], set.t[3 * k + 2]}},
                    {"rotation", {set.r[4 * k], set.r[4 * k + 1], set.r[4 * k + 2], set.r[4 * k + 3]}},
                    {"scale", {set.s[3 * k], set.s[3 * k + 1], set.s[3 * k + 2]}}},
                   false));
    // The instanced node itself is not drawn: here it is a node without a mesh.
    children.push_back(d.node({{"mesh", sc.mesh}, {"translation", {0, 3, 0}}}, false));
    d.node({{"translation", {1, -2, 0.5}}, {"scale", {2, 2, 2}}, {"children", children}});
    return d.write(file);
}

/// The pixel means (RGB, row by row) of a small, quick render of `file` as `sahara view` frames it.
std::vector<double> render_view(const fs::path& file) {
    SceneDesc desc = make_view_scene(load_model(file), true, ViewOptions{}, file.string());
    desc.render.width = 48;
    desc.render.height = 36;
    desc.render.spp = 16;
    desc.render.max_depth = 3;
    Film film(desc.render.width, desc.render.height);
    test::render_into(desc, film);
    std::vector<double> out;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const Vec3d p = film.sum(x, y) / double(film.count(x, y));
            out.insert(out.end(), {p.x, p.y, p.z});
        }
    return out;
}

/// A document with one triangle mesh on node 0 and the given instancing attributes.
Doc instancing_doc(const json& attrs) {
    Doc d;
    d.node({{"mesh", d.mesh(d.positions(kTriangle))}, {"extensions", {{kExt, {{"attributes", attrs}}}}}});
    return d;
}

void check_matrix(const Mat4& got, const Mat4& want, double tol) {
    for (size_t r = 0; r < 4; ++r)
        for (size_t c = 0; c < 4; ++c) CHECK(got.m[r][c] == doctest::Approx(want.m[r][c]).epsilon(tol));
}

}  // namespace

TEST_CASE("EXT_mesh_gpu_instancing: a grid of instances is one prototype and renders like separate nodes") {
    const fs::path dir = scratch("gpu_instancing_grid");
    const Placements set = grid_instances(3);
    const fs::path instanced = write_instanced(dir / "instanced.gltf", set);
    const fs::path separate = write_separate(dir / "separate.gltf", set);

    const LoadedModel model = load_model(instanced);
    REQUIRE(model.prototypes.size() == 1);
    CHECK(model.instances.size() == set.size());
    CHECK(model.meshes.size() == 2);  // the prototype's mesh and the child's world-space copy
    const LoadedModel reference = load_model(separate);
    CHECK(reference.instances.empty());
    CHECK(triangles(reference) == (set.size() + 1) * triangles(model) / 2);

    // Same framing: the view camera depends only on the bounds.
    const SceneDesc a = make_view_scene(load_model(instanced), true, ViewOptions{}, "a");
    const SceneDesc b = make_view_scene(load_model(separate), true, ViewOptions{}, "b");
    for (int k = 0; k < 3; ++k) {
        CHECK(a.camera.position[k] == doctest::Approx(b.camera.position[k]).epsilon(1e-4));
        CHECK(a.camera.look_at[k] == doctest::Approx(b.camera.look_at[k]).epsilon(1e-4));
    }

    const std::vector<double> ia = render_view(instanced), ib = render_view(separate);
    double diff = 0, total = 0;
    for (size_t k = 0; k < ia.size(); ++k) {
        diff += std::abs(ia[k] - ib[k]);
        total += std::abs(ib[k]);
    }
    // Instanced and flat intersection round differently, so paths part ways now
    // and then; a misplaced or missing instance moves far more than this.
    CHECK(diff / total < 0.005);
}

TEST_CASE("EXT_mesh_gpu_instancing: the instances bake to the triangles of separate nodes") {
    const fs::path dir = scratch("gpu_instancing_bake");
    const Placements set = grid_instances(2);
    LoadedModel baked = load_model(write_instanced(dir / "instanced.gltf", set));
    bake_instances(baked);
    CHECK(baked.prototypes.empty());
    CHECK(baked.instances.empty());
    const LoadedModel reference = load_model(write_separate(dir / "separate.gltf", set));
    REQUIRE(baked.meshes.size() == reference.meshes.size());
    CHECK(triangles(baked) == triangles(reference));
    const Bounds3 bb = bounds(baked), rb = bounds(reference);
    for (int k = 0; k < 3; ++k) {
        CHECK(bb.lo[k] == doctest::Approx(rb.lo[k]).epsilon(1e-5));
        CHECK(bb.hi[k] == doctest::Approx(rb.hi[k]).epsilon(1e-5));
    }
    // The BVH tools and the Python module read every drawn triangle.
    CHECK(read_mesh_triangles(dir / "instanced.gltf").triangle_count() == triangles(reference));
}

TEST_CASE("EXT_mesh_gpu_instancing: normalized short rotations equal their float quaternions") {
    const fs::path dir = scratch("gpu_instancing_short");
    const double h = std::sqrt(0.5);
    const std::vector<std::vector<double>> quats = {{0, 0, h, h}, {0.5, 0.5, 0.5, 0.5}, {0, -1, 0, 0}};
    std::vector<int16_t> shorts;
    for (const auto& q : quats)
        for (double c : q) shorts.push_back(int16_t(std::lround(c * 32767.0)));
    Doc d = instancing_doc(json::object());
    d.j["nodes"][0]["extensions"][kExt]["attributes"]["ROTATION"] =
        d.accessor(shorts, 5122, "VEC4", quats.size(), true);
    d.j["extensionsRequired"] = {kExt, "KHR_mesh_quantization"};
    const LoadedModel m = load_model(d.write(dir / "short.gltf"));
    REQUIRE(m.instances.size() == quats.size());
    for (size_t k = 0; k < quats.size(); ++k)
        check_matrix(m.instances[k].world_from_object,
                     Mat4::rotate_quaternion(quats[k][0], quats[k][1], quats[k][2], quats[k][3]), 1e-4);
}

TEST_CASE("EXT_mesh_gpu_instancing: missing attributes default to identity") {
    const fs::path dir = scratch("gpu_instancing_defaults");
    {
        Doc d = instancing_doc(json::object());
        d.j["nodes"][0]["extensions"][kExt]["attributes"]["TRANSLATION"] =
            d.accessor(std::vector<float>{1, 2, 3, -4, 5, -6}, 5126, "VEC3", 2);
        const LoadedModel m = load_model(d.write(dir / "translation.gltf"));
        REQUIRE(m.instances.size() == 2);
        check_matrix(m.instances[0].world_from_object, Mat4::translate({1, 2, 3}), 1e-6);
        check_matrix(m.instances[1].world_from_object, Mat4::translate({-4, 5, -6}), 1e-6);
    }
    {
        Doc d = instancing_doc(json::object());
        d.j["nodes"][0]["extensions"][kExt]["attributes"]["SCALE"] =
            d.accessor(std::vector<float>{2, 3, 4}, 5126, "VEC3", 1);
        d.j["nodes"][0]["translation"] = {0, 1, 0};  // the node's own transform comes first
        const LoadedModel m = load_model(d.write(dir / "scale.gltf"));
        REQUIRE(m.instances.size() == 1);
        check_matrix(m.instances[0].world_from_object, Mat4::translate({0, 1, 0}) * Mat4::scale({2, 3, 4}),
                     1e-6);
    }
}

TEST_CASE("EXT_mesh_gpu_instancing: custom attributes alone give the instance count at the identity") {
    // The specification makes every attribute optional and asks only that all of a
    // node's attributes, custom ones (`_ID`, ...) included, have the same count.
    const fs::path dir = scratch("gpu_instancing_custom");
    Doc d = instancing_doc(json::object());
    json& attrs = d.j["nodes"][0]["extensions"][kExt]["attributes"];
    attrs["_ID"] = d.accessor(std::vector<uint16_t>{7, 8, 9}, 5123, "SCALAR", 3);
    attrs["_FEATURE_ID_0"] = d.accessor(std::vector<float>{0, 1, 2}, 5126, "SCALAR", 3);
    d.j["nodes"][0]["translation"] = {1, 2, 3};
    const LoadedModel m = load_model(d.write(dir / "custom.gltf"));
    REQUIRE(m.prototypes.size() == 1);
    REQUIRE(m.instances.size() == 3);
    for (const InstanceDesc& in : m.instances)
        check_matrix(in.world_from_object, Mat4::translate({1, 2, 3}), 1e-9);

    // Beside a transform attribute they are ignored; the transforms place the instances.
    attrs["TRANSLATION"] = d.accessor(std::vector<float>{0, 0, 0, 2, 0, 0, 4, 0, 0}, 5126, "VEC3", 3);
    const LoadedModel moved = load_model(d.write(dir / "moved.gltf"));
    REQUIRE(moved.instances.size() == 3);
    check_matrix(moved.instances[2].world_from_object, Mat4::translate({5, 2, 3}), 1e-9);
}

TEST_CASE("EXT_mesh_gpu_instancing: a morphed mesh is instanced with the node's weights") {
    const fs::path dir = scratch("gpu_instancing_morph");
    Doc d = instancing_doc(json::object());
    d.j["nodes"][0]["extensions"][kExt]["attributes"]["TRANSLATION"] =
        d.accessor(std::vector<float>{0, 0, 0, 5, 0, 0}, 5126, "VEC3", 2);
    const int target = d.positions({0, 0, 1, 0, 0, 1, 0, 0, 1});
    d.j["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", target}}};
    d.j["nodes"][0]["weights"] = {0.5};
    const LoadedModel m = load_model(d.write(dir / "morph.gltf"));
    REQUIRE(m.prototypes.size() == 1);
    CHECK(m.instances.size() == 2);
    REQUIRE(m.meshes.size() == 1);
    for (const Vec3& p : m.meshes[0].positions) CHECK(p.z == doctest::Approx(0.5));
}

TEST_CASE("EXT_mesh_gpu_instancing: 10000 instances store the triangles of one mesh") {
    const fs::path dir = scratch("gpu_instancing_many");
    const Placements set = grid_instances(100);
    Scenario sc = grid_scenario();
    const size_t n = set.size();
    sc.d.node({{"mesh", sc.mesh},
               {"extensions",
                {{kExt,
                  {{"attributes",
                    {{"TRANSLATION", sc.d.accessor(set.t, 5126, "VEC3", n)},
                     {"ROTATION", sc.d.accessor(set.r, 5126, "VEC4", n)}}}}}}}});
    const fs::path file = sc.d.write(dir / "many.gltf");
    LoadedModel m = load_model(file);
    REQUIRE(m.meshes.size() == 1);
    const size_t one = m.meshes[0].triangle_count();
    CHECK(one == 18);
    CHECK(m.instances.size() == 10000);
    SceneDesc desc;
    desc.materials.push_back(default_material());
    merge_loaded_model(desc, std::move(m), std::nullopt);
    const Scene scene = build_scene(desc);
    CHECK(scene.triangles.size() == 0);
    REQUIRE(scene.instances() != nullptr);
    CHECK(scene.instances()->unique_triangle_count() == one);
    CHECK(scene.instances()->instanced_triangle_count() == one * 10000);
}

TEST_CASE("EXT_mesh_gpu_instancing: bad attributes are InputErrors naming the node's attribute") {
    const fs::path dir = scratch("gpu_instancing_errors");
    const std::string attrs = "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes";
    const float nan = std::numeric_limits<float>::quiet_NaN();
    struct Case {
        const char* what;
        std::function<void(Doc&)> edit;
        std::string element, message;
    };
    auto set = [](Doc& d, const char* name, int accessor) {
        d.j["nodes"][0]["extensions"][kExt]["attributes"][name] = accessor;
    };
    const std::vector<Case> cases = {
        {"counts differ",
         [&](Doc& d) {
             set(d, "TRANSLATION", d.accessor(std::vector<float>{0, 0, 0, 1, 1, 1}, 5126, "VEC3", 2));
             set(d, "SCALE", d.accessor(std::vector<float>{1, 1, 1}, 5126, "VEC3", 1));
         },
         attrs + ".SCALE", "another attribute has 2"},
        {"wrong type",
         [&](Doc& d) {
             set(d, "TRANSLATION", d.accessor(std::vector<float>{0, 0, 0, 1}, 5126, "VEC4", 1));
         },
         attrs + ".TRANSLATION", "must be a VEC3"},
        {"integer rotation not normalized",
         [&](Doc& d) {
             set(d, "ROTATION", d.accessor(std::vector<int16_t>{0, 0, 0, 1}, 5122, "VEC4", 1));
         },
         attrs + ".ROTATION", "componentType"},
        {"non-unit quaternion",
         [&](Doc& d) {
             set(d, "ROTATION", d.accessor(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 2}, 5126, "VEC4", 2));
         },
         attrs + ".ROTATION", "instance 1 is not a unit quaternion"},
        {"NaN quaternion",
         [&](Doc& d) {
             set(d, "ROTATION", d.accessor(std::vector<float>{0, 0, nan, 1}, 5126, "VEC4", 1));
         },
         attrs + ".ROTATION", "not a finite number"},
        {"accessor out of range", [&](Doc& d) { set(d, "SCALE", 99); }, attrs + ".SCALE",
         "accessor 99 does not exist"},
        {"not an index", [&](Doc& d) { d.j["nodes"][0]["extensions"][kExt]["attributes"]["SCALE"] = "big"; },
         attrs + ".SCALE", "must be an accessor index"},
        {"zero count",
         [&](Doc& d) {
             set(d, "TRANSLATION", d.accessor(std::vector<float>{0, 0, 0}, 5126, "VEC3", 1));
             d.j["accessors"].back()["count"] = 0;
         },
         attrs + ".TRANSLATION", "count 0"},
        {"no attributes", [&](Doc& d) { d.j["nodes"][0]["extensions"][kExt].erase("attributes"); }, attrs,
         "has no attributes"},
        {"attributes not an object",
         [&](Doc& d) {
             d.j["nodes"][0]["extensions"][kExt]["attributes"] = {1, 2};
         },
         attrs, "is not an object"},
        {"custom attribute count differs",
         [&](Doc& d) {
             set(d, "TRANSLATION", d.accessor(std::vector<float>{0, 0, 0, 1, 1, 1}, 5126, "VEC3", 2));
             set(d, "_FEATURE_ID_0", d.accessor(std::vector<float>{0, 1, 2}, 5126, "SCALAR", 3));
         },
         attrs + "._FEATURE_ID_0", "has 3 instances, another attribute has 2"},
        {"custom attribute accessor out of range", [&](Doc& d) { set(d, "_ID", 42); }, attrs + "._ID",
         "accessor 42 does not exist"},
    };
    for (const Case& c : cases) {
        const std::string what = c.what;
        CAPTURE(what);
        Doc d = instancing_doc(json::object());
        c.edit(d);
        const fs::path file = d.write(dir / "bad.gltf");
        const std::string err = error_of([&] { load_model(file); });
        CAPTURE(err);
        CHECK(err.find(file.string()) != std::string::npos);
        CHECK(err.find(c.element + ":") != std::string::npos);
        CHECK(err.find(c.message) != std::string::npos);
    }
}

TEST_CASE("EXT_mesh_gpu_instancing in extensionsRequired loads and an unknown required extension does not") {
    const fs::path dir = scratch("gpu_instancing_required");
    Doc d = instancing_doc(json::object());
    d.j["nodes"][0]["extensions"][kExt]["attributes"]["TRANSLATION"] =
        d.accessor(std::vector<float>{0, 0, 0, 2, 0, 0}, 5126, "VEC3", 2);
    d.j["extensionsUsed"] = {kExt};
    d.j["extensionsRequired"] = {kExt};
    CHECK(load_model(d.write(dir / "required.gltf")).instances.size() == 2);
    d.j["extensionsRequired"] = {kExt, "EXT_made_up"};
    const std::string err = error_of([&] { load_model(d.write(dir / "unknown.gltf")); });
    CHECK(err.find("extensionsRequired: EXT_made_up is not supported") != std::string::npos);
}
