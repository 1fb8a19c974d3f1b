// KHR_materials_variants: a variant chosen by name gives each primitive its
// mapped material (the default where it has no mapping for that variant), in
// the loader and through a scene file's "variant" key; an unknown name and bad
// mappings are InputErrors naming the file and the element. The documents are
// built here.
#include "gltf_test_doc.h"
#include "io/scene_parser.h"
#include "render_test_util.h"

using namespace sahara;
using namespace sahara::test::gltf;
using sahara::test::radiance_along;

namespace {

const char* kExt = "KHR_materials_variants";

/// An unlit material: a camera ray returns its base colour exactly.
json unlit(const char* name, std::vector<double> rgb) {
    return {{"name", name},
            {"pbrMetallicRoughness", {{"baseColorFactor", {rgb[0], rgb[1], rgb[2], 1.0}}}},
            {"extensions", {{"KHR_materials_unlit", json::object()}}}};
}

/// Two unit quads side by side in z = 0 (x in [-1, 0] and [0, 1], y in [-0.5, 0.5]),
/// each its own primitive with the grey material 0. Variants "Red" and "Blue":
/// the left quad is red in Red and blue in Blue; the right quad maps only Blue.
Doc variants_doc() {
    Doc d;
    const auto quad = [&d](float x0) {
        const std::vector<float> p = {x0, -0.5f, 0, x0 + 1, -0.5f, 0, x0 + 1, 0.5f, 0, x0, 0.5f, 0};
        return d.accessor(p, 5126, "VEC3", 4);
    };
    const int idx = d.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR", 6);
    const int left = quad(-1), right = quad(0);
    const auto mapping = [](int material, std::vector<int> variants) {
        return json{{"material", material}, {"variants", variants}};
    };
    json prims = json::array();
    prims.push_back({{"attributes", {{"POSITION", left}}},
                     {"indices", idx},
                     {"material", 0},
                     {"extensions", {{kExt, {{"mappings", {mapping(1, {0}), mapping(2, {1})}}}}}}});
    prims.push_back({{"attributes", {{"POSITION", right}}},
                     {"indices", idx},
                     {"material", 0},
                     {"extensions", {{kExt, {{"mappings", {mapping(2, {1})}}}}}}});
    d.j["meshes"].push_back({{"primitives", prims}});
    d.node({{"mesh", 0}});
    d.j["materials"] = {unlit("grey", {0.5, 0.5, 0.5}), unlit("red", {1, 0, 0}), unlit("blue", {0, 0, 1})};
    d.j["extensions"][kExt] = {{"variants", {{{"name", "Red"}}, {{"name", "Blue"}}}}};
    d.j["extensionsUsed"] = {kExt, "KHR_materials_unlit"};
    return d;
}

/// The material names of the loaded primitives, left quad first.
std::vector<std::string> material_names(const LoadedModel& m) {
    std::vector<std::string> out;
    for (const TriangleMesh& mesh : m.meshes) out.push_back(m.materials[mesh.material].name);
    return out;
}

/// A scene file looking down -z at the quads, black background, that loads `model` with `extra` keys.
fs::path write_scene(const fs::path& dir, const json& extra) {
    json object = {{"type", "mesh"}, {"file", "model.gltf"}};
    for (auto& [k, v] : extra.items()) object[k] = v;
    const json scene = {
        {"format", "scene/1"},
        {"camera", {{"position", {0, 0, 4}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"vfov", 40}}},
        {"background", {{"type", "constant"}, {"color", {0, 0, 0}}}},
        {"objects", {object}}};
    write_text(dir / "scene.json", scene.dump());
    return dir / "scene.json";
}

/// What a camera ray straight down at (x, 0) sees.
Rgb seen_at(const SceneDesc& desc, float x) {
    return radiance_along(desc, IntegratorType::path, Ray{Vec3(x, 0, 4), Vec3(0, 0, -1)}, 4);
}

}  // namespace

TEST_CASE("KHR_materials_variants: each primitive takes its mapping for the chosen variant") {
    const fs::path dir = scratch("variants_loader");
    const fs::path file = variants_doc().write(dir / "model.gltf");
    const LoadedModel none = load_model(file);
    CHECK(material_names(none) == std::vector<std::string>{"grey", "grey"});
    CHECK(!none.variant);
    CHECK(none.variants == std::vector<std::string>{"Red", "Blue"});
    const LoadedModel red = load_model(file, Mat4::identity(), SharedMeshes::copy, "Red");
    CHECK(material_names(red) == std::vector<std::string>{"red", "grey"});  // the right quad has no Red
    CHECK(red.variant == std::optional<std::string>("Red"));
    const LoadedModel blue = load_model(file, Mat4::identity(), SharedMeshes::copy, "Blue");
    CHECK(material_names(blue) == std::vector<std::string>{"blue", "blue"});
}

TEST_CASE("KHR_materials_variants: a scene file's variant key renders that variant's colours") {
    const fs::path dir = scratch("variants_render");
    variants_doc().write(dir / "model.gltf");
    const SceneDesc plain = parse_scene_file(write_scene(dir, json::object()));
    CHECK(seen_at(plain, -0.5f) == Rgb(0.5f, 0.5f, 0.5f));
    CHECK(seen_at(plain, 0.5f) == Rgb(0.5f, 0.5f, 0.5f));
    const SceneDesc red = parse_scene_file(write_scene(dir, {{"variant", "Red"}}));
    CHECK(seen_at(red, -0.5f) == Rgb(1, 0, 0));
    CHECK(seen_at(red, 0.5f) == Rgb(0.5f, 0.5f, 0.5f));
    const SceneDesc blue = parse_scene_file(write_scene(dir, {{"variant", "Blue"}}));
    CHECK(seen_at(blue, -0.5f) == Rgb(0, 0, 1));
    CHECK(seen_at(blue, 0.5f) == Rgb(0, 0, 1));
}

TEST_CASE("KHR_materials_variants: an unknown variant names the file and lists its variants") {
    const fs::path dir = scratch("variants_unknown");
    const fs::path file = variants_doc().write(dir / "model.gltf");
    std::string err = error_of([&] { load_model(file, Mat4::identity(), SharedMeshes::copy, "Green"); });
    CHECK(err == file.string() +
                     ": KHR_materials_variants: no material variant named 'Green'; the file has: "
                     "Red, Blue");
    // Through a scene file: the mesh object's file names it, then the model's message.
    err = error_of([&] { parse_scene_file(write_scene(dir, {{"variant", "Green"}})); });
    CHECK(err.find("objects[0].file") != std::string::npos);
    CHECK(err.find("no material variant named 'Green'; the file has: Red, Blue") != std::string::npos);
    err = error_of([&] { parse_scene_file(write_scene(dir, {{"variant", 3}})); });
    CHECK(err.find("objects[0].variant") != std::string::npos);
    // A file without variants, and an OBJ file, have none to choose.
    const fs::path plain = Doc().write(dir / "plain.gltf");
    err = error_of([&] { load_model(plain, Mat4::identity(), SharedMeshes::copy, "Red"); });
    CHECK(err.find("no material variant named 'Red', the file has none") != std::string::npos);
    write_text(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    err = error_of([&] { load_model(dir / "tri.obj", Mat4::identity(), SharedMeshes::copy, "Red"); });
    CHECK(err.find("only glTF files have material variants") != std::string::npos);
}

TEST_CASE("KHR_materials_variants: bad mappings are InputErrors naming the mapping") {
    const fs::path dir = scratch("variants_bad");
    const std::string mappings = "meshes[0].primitives[1].extensions.KHR_materials_variants.mappings";
    struct Case {
        const char* what;
        json mapping;
        std::string element, message;
    };
    const std::vector<Case> cases = {
        {"material out of range",
         {{"material", 9}, {"variants", {1}}},
         mappings + "[0].material",
         "material 9 does not exist (the file has 3)"},
        {"variant out of range",
         {{"material", 1}, {"variants", {0, 5}}},
         mappings + "[0].variants[1]",
         "variant 5 does not exist (the file has 2)"},
        {"variant not an index",
         {{"material", 1}, {"variants", {"Red"}}},
         mappings + "[0].variants[0]",
         "must be a variant index"},
        {"no variants", {{"material", 1}}, mappings + "[0]", "needs a material and a variants array"},
    };
    for (const Case& c : cases) {
        const std::string what = c.what;
        CAPTURE(what);
        Doc d = variants_doc();
        d.j["meshes"][0]["primitives"][1]["extensions"][kExt]["mappings"] = {c.mapping};
        const fs::path file = d.write(dir / "bad.gltf");
        const std::string err =
            error_of([&] { load_model(file, Mat4::identity(), SharedMeshes::copy, "Red"); });
        CAPTURE(err);
        CHECK(err.find(file.string() + ": " + c.element + ": " + c.message) != std::string::npos);
        // Without a variant the mappings are not used, and the file loads as before.
        CHECK(load_model(file).meshes.size() == 2);
    }
}
