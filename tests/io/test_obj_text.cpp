// OBJ text tinyobjloader alone reads wrongly: several files on one mtllib line,
// names with spaces, and line continuations.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "base/error.h"
#include "base/log.h"
#include "io/model_loader.h"
#include "scratch_dir.h"

using namespace sahara;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return test::scratch_dir("obj_text_" + name); }

void write(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

/// The material names the model's triangles use.
std::set<std::string> used_materials(const LoadedModel& m) {
    std::set<std::string> names;
    for (const TriangleMesh& mesh : m.meshes) {
        if (mesh.material_ids.empty()) names.insert(m.materials.at(mesh.material).name);
        for (uint32_t id : mesh.material_ids) names.insert(m.materials.at(id).name);
    }
    return names;
}

const std::string kTwoTriangles = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";

}  // namespace

TEST_CASE("every file of an mtllib line with several files is read") {
    const fs::path dir = scratch("multi");
    write(dir / "a.mtl", "newmtl red\nKd 1 0 0\n");
    write(dir / "b.mtl", "newmtl green\nKd 0 1 0\n");
    write(dir / "m.obj",
          "mtllib a.mtl b.mtl\n" + kTwoTriangles + "usemtl red\nf 1 2 3\nusemtl green\nf 2 4 3\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    CHECK(used_materials(m) == std::set<std::string>{"red", "green"});
    // Named again on a later line, a file is not read twice.
    write(dir / "twice.obj", "mtllib a.mtl\nmtllib a.mtl b.mtl\n" + kTwoTriangles +
                                 "usemtl red\nf 1 2 3\nusemtl green\nf 2 4 3\n");
    CHECK(load_obj(dir / "twice.obj").materials.size() == 2);
}

TEST_CASE("material and library names with spaces are kept whole") {
    const fs::path dir = scratch("spaces");
    write(dir / "my mats.mtl", "newmtl red paint\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
    write(dir / "m.obj",
          "mtllib my mats.mtl\n" + kTwoTriangles + "usemtl red paint\nf 1 2 3\nusemtl green\nf 2 4 3\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    CHECK(used_materials(m) == std::set<std::string>{"red paint", "green"});
    for (const MaterialDesc& mat : m.materials)
        if (mat.name == "red paint") CHECK(mat.albedo.color == Rgb(1, 0, 0));
}

TEST_CASE("OBJ line continuations join lines") {
    const fs::path dir = scratch("continue");
    write(dir / "m.obj", "# a comment ending in \\\nv 0 0 \\\r\n2\nv 1 0 2\nv 0 1 2\nf 1 \\\n 2 3\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].indices.size() == 3);
    for (const Vec3& p : m.meshes[0].positions) CHECK(p.z == 2.0f);
}

TEST_CASE("OBJ data lines with a trailing comment or an empty last index slot load") {
    const fs::path dir = scratch("trailing");
    write(dir / "m.obj",
          "v 0 0 0 # origin\nv 1 0 0\nv 0 1 0#corner\nvt 0 0\nvt 1 0\nvt 0 1\n"
          "f 1/1/ 2/2/ 3/3/ # a face\nf 1// 3// 2//\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].indices.size() == 6);
    CHECK(m.meshes[0].uvs.size() == m.meshes[0].positions.size());
}

TEST_CASE("OBJ vertex colours load sRGB-decoded to linear and tag the material") {
    const fs::path dir = scratch("colours");
    write(dir / "m.obj", "v 0 0 0 1 0 0\nv 1 0 0 0 0.5 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
    const int before = warning_count();
    const LoadedModel m = load_obj(dir / "m.obj");
    CHECK(warning_count() == before);
    REQUIRE(m.meshes.size() == 1);
    const TriangleMesh& mesh = m.meshes[0];
    REQUIRE(mesh.colors.size() == mesh.positions.size());
    CHECK(mesh.positions[1] == Vec3(1, 0, 0));
    CHECK(mesh.colors[0] == Rgb(1, 0, 0));
    CHECK(mesh.colors[1].y == doctest::Approx(0.214f).epsilon(1e-3));  // 0.5 sRGB
    CHECK(mesh.colors[2] == Rgb(0, 0, 1));
    CHECK(m.materials[mesh.material].vertex_colors);
}

TEST_CASE("OBJ vertex colours written as 0-255 are scaled to 0-1") {
    const fs::path dir = scratch("colours255");
    write(dir / "m.obj", "v 0 0 0 255 0 0\nv 1 0 0 0 128 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    REQUIRE(m.meshes.size() == 1);
    const TriangleMesh& mesh = m.meshes[0];
    REQUIRE(mesh.colors.size() == 3);
    CHECK(mesh.colors[0] == Rgb(1, 0, 0));
    CHECK(mesh.colors[1].y == doctest::Approx(0.2158f).epsilon(1e-3));    // 128/255 sRGB
    CHECK(mesh.colors[2].z == doctest::Approx(0.000304f).epsilon(1e-2));  // 1/255 sRGB
}

TEST_CASE("OBJ vertex colours on only some v lines are not loaded") {
    const fs::path dir = scratch("somecolours");
    write(dir / "m.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].colors.empty());
    CHECK_FALSE(m.materials[m.meshes[0].material].vertex_colors);
}

TEST_CASE("a NaN or negative OBJ vertex colour is an InputError naming the vertex") {
    const fs::path dir = scratch("nancolour");
    const std::pair<const char*, const char*> bad[] = {{"nan", "colour is not a finite number"},
                                                       {"1e999", "colour is not a finite number"},
                                                       {"-0.5", "colour is negative"}};
    for (const auto& [value, what] : bad) {
        write(dir / "m.obj",
              std::string("v 0 0 0 1 1 1\nv 1 0 0 0 ") + value + " 0\nv 0 1 0 1 1 1\nf 1 2 3\n");
        std::string message;
        try {
            load_obj(dir / "m.obj");
        } catch (const InputError& e) {
            message = e.what();
        }
        CHECK(message == (dir / "m.obj").string() + ": v #2: " + what);
    }
}

TEST_CASE("an OBJ face of two vertices is one warning") {
    const fs::path dir = scratch("two");
    write(dir / "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n");
    const int before = warning_count();
    const LoadedModel m = load_obj(dir / "m.obj");
    CHECK(warning_count() - before == 1);
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].indices.size() == 3);
}
