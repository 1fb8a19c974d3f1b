#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "base/error.h"
#include "base/log.h"
#include "error_message.h"
#include "io/image_io.h"
#include "io/mesh_utils.h"
#include "io/model_loader.h"
#include "mesh_fixtures.h"
#include "test_data.h"
#include "scratch_dir.h"

using namespace sahara;
using sahara::test::count_repeated_corner_triangles;
using sahara::test::error_of;
using sahara::test::kTestData;
using sahara::test::make_scan_mesh_70k;
namespace fs = std::filesystem;

namespace {

/// A fresh scratch folder per test.
fs::path scratch(const std::string& name) { return test::scratch_dir("obj_" + name); }

void write(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

/// Counts what an OBJ file says by reading its lines directly (independent of
/// the loader): triangles (n - 2 per face) and the box around all `v` lines.
struct ObjFacts {
    size_t triangles = 0;
    Bounds3 box;
};

ObjFacts count_obj(const fs::path& file) {
    ObjFacts f;
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);) {
        std::istringstream ss(line);
        std::string tag;
        ss >> tag;
        if (tag == "v") {
            Vec3 p;
            ss >> p.x >> p.y >> p.z;
            f.box.extend(p);
        } else if (tag == "f") {
            size_t n = 0;
            for (std::string tok; ss >> tok;) ++n;
            f.triangles += n - 2;
        }
    }
    return f;
}

size_t triangles(const LoadedModel& m) {
    size_t n = 0;
    for (const auto& mesh : m.meshes) n += mesh.triangle_count();
    return n;
}

Bounds3 bounds(const LoadedModel& m) {
    Bounds3 b;
    for (const auto& mesh : m.meshes) b.extend(mesh_bounds(mesh));
    return b;
}

double area(const TriangleMesh& m) {
    double a = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
        const Vec3d p0(m.positions[m.indices[3 * t]]), p1(m.positions[m.indices[3 * t + 1]]),
            p2(m.positions[m.indices[3 * t + 2]]);
        a += 0.5 * length(cross(p1 - p0, p2 - p0));
    }
    return a;
}

/// What load_model must give for an OBJ file: its triangles (counted from the file)
/// minus the zero-area ones, and the materials and textures it names.
struct ObjExpect {
    size_t degenerate, materials, textures;
};

void check_obj_loads(const fs::path& file, size_t file_tris, const ObjExpect& e) {
    CAPTURE(file.string());
    const ObjFacts facts = count_obj(file);
    REQUIRE(facts.triangles == file_tris);
    set_log_quiet(true);
    const LoadedModel m = load_model(file);
    set_log_quiet(false);
    CHECK(triangles(m) == file_tris - e.degenerate);
    CHECK(m.dropped_degenerate == e.degenerate);
    CHECK(m.materials.size() == e.materials);
    CHECK(m.textures.size() == e.textures);
    const Bounds3 b = bounds(m);
    for (int k = 0; k < 3; ++k) {
        CHECK(b.lo[k] == doctest::Approx(facts.box.lo[k]));
        CHECK(b.hi[k] == doctest::Approx(facts.box.hi[k]));
    }
    for (const auto& mesh : m.meshes) {
        CHECK((mesh.normals.empty() || mesh.normals.size() == mesh.positions.size()));
        CHECK((mesh.uvs.empty() || mesh.uvs.size() == mesh.positions.size()));
    }
}

/// Writes `m` as OBJ text: `v` lines that read back to the same floats, then one
/// `f` line per triangle (1-based).
void write_obj(const fs::path& file, const TriangleMesh& m) {
    std::ofstream out(file);
    out << std::setprecision(std::numeric_limits<float>::max_digits10);
    for (const Vec3& p : m.positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (size_t t = 0; t < m.triangle_count(); ++t)
        out << "f " << m.indices[3 * t] + 1 << ' ' << m.indices[3 * t + 1] + 1 << ' '
            << m.indices[3 * t + 2] + 1 << '\n';
}

}  // namespace

TEST_CASE("the OBJ files in tests/data load with their published counts") {
    // Triangle counts from tests/data/SOURCES.md; spider has 56 zero-area triangles.
    // Materials: newmtl entries (cornell 8, spider 5) or the default one; textures: map_Kd files.
    check_obj_loads(kTestData / "obj/spot/spot.obj", 5856, {0, 1, 0});
    check_obj_loads(kTestData / "obj/cornell-box/CornellBox-Original.obj", 36, {0, 8, 0});
    check_obj_loads(kTestData / "obj/spider/spider.obj", 1368, {56, 5, 5});
}

TEST_CASE("a 70k-triangle scan-like OBJ loads whole, its zero-area triangles, and only those, are dropped") {
    // The big triangle-only file with holes, slivers and degenerate triangles that
    // scanned models are; the expected counts come from the generated mesh itself.
    const TriangleMesh scan = make_scan_mesh_70k();
    const size_t degenerate = count_repeated_corner_triangles(scan);
    REQUIRE(scan.triangle_count() > 60000);
    REQUIRE(degenerate > 0);
    const fs::path file = scratch("scan") / "scan.obj";
    write_obj(file, scan);
    check_obj_loads(file, scan.triangle_count(), {degenerate, 1, 0});
}

TEST_CASE("an OBJ of quads and triangles with per-vertex normals (f v//vn) is triangulated") {
    // A closed sphere in quads, with triangle fans at the poles, and a `vn` for every vertex.
    const int rings = 12, segments = 20;
    std::ostringstream obj;
    obj << "v 0 1 0\nvn 0 1 0\n";
    for (int r = 1; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const double th = std::numbers::pi * r / rings, ph = 2 * std::numbers::pi * s / segments;
            const double x = std::sin(th) * std::cos(ph), y = std::cos(th), z = std::sin(th) * std::sin(ph);
            obj << "v " << x << ' ' << y << ' ' << z << "\nvn " << x << ' ' << y << ' ' << z << '\n';
        }
    obj << "v 0 -1 0\nvn 0 -1 0\n";
    const int south = 2 + (rings - 1) * segments;
    auto at = [&](int r, int s) { return 2 + (r - 1) * segments + s % segments; };
    // One face line; every corner's normal has the corner's own index (f v//vn).
    auto face = [&](std::initializer_list<int> corners) {
        obj << 'f';
        for (int v : corners) obj << ' ' << v << "//" << v;
        obj << '\n';
    };
    for (int s = 0; s < segments; ++s) face({1, at(1, s + 1), at(1, s)});
    for (int r = 1; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) face({at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)});
    for (int s = 0; s < segments; ++s) face({south, at(rings - 1, s), at(rings - 1, s + 1)});
    const fs::path file = scratch("quads") / "quads.obj";
    write(file, obj.str());
    const size_t tris = size_t(2 * segments + 2 * (rings - 2) * segments);
    check_obj_loads(file, tris, {0, 1, 0});
    const LoadedModel m = load_model(file);
    REQUIRE(!m.meshes.empty());
    for (const TriangleMesh& mesh : m.meshes) {
        REQUIRE(mesh.normals.size() == mesh.positions.size());
        // The file's normals are the unit sphere's: each equals its own vertex position.
        for (size_t v = 0; v < mesh.positions.size(); ++v)
            CHECK(length(mesh.normals[v] - normalize(mesh.positions[v])) < 1e-4f);
    }
}

TEST_CASE("OBJ materials: Kd, Ke emitters, map_Kd with Windows paths") {
    const LoadedModel box = load_obj(kTestData / "obj/cornell-box/CornellBox-Original.obj");
    int emitters = 0;
    for (const MaterialDesc& m : box.materials) {
        if (m.name == "light") {
            ++emitters;
            CHECK(m.type == MaterialType::emissive);
            CHECK(m.radiance.color == Rgb(17, 12, 4));
        } else {
            CHECK(m.type == MaterialType::lambertian);
        }
        if (m.name == "leftWall") CHECK(m.albedo.color == Rgb(0.63f, 0.065f, 0.05f));
    }
    CHECK(emitters == 1);

    const LoadedModel spider = load_obj(kTestData / "obj/spider/spider.obj");
    for (const MaterialDesc& m : spider.materials) {
        CAPTURE(m.name);
        REQUIRE(m.albedo.kind == ColorSource::Kind::texture);
        const TextureDesc& t = spider.textures.at(size_t(m.albedo.texture));
        CHECK(t.image->width > 0);
        CHECK(t.image->rgba.size() == size_t(t.image->width) * size_t(t.image->height) * 4);
    }
    for (const TriangleMesh& mesh : spider.meshes) CHECK(mesh.uvs.size() == mesh.positions.size());
}

TEST_CASE("concave polygons are ear-clipped, not fanned") {
    // A 66-vertex comb: 32 teeth; a fan from vertex 0 would cover the gaps.
    std::ostringstream obj;
    const int teeth = 16;
    std::vector<std::pair<float, float>> pts;
    for (int i = 0; i < teeth; ++i) {
        pts.push_back({float(2 * i), 1});
        pts.push_back({float(2 * i) + 1, 1});
        pts.push_back({float(2 * i) + 1, 3});
        pts.push_back({float(2 * i) + 2, 3});
    }
    pts.push_back({float(2 * teeth), 0});
    pts.push_back({0, 0});
    // The comb's area: base strip 2*teeth x 1 plus teeth 1 x 2 each... computed by the shoelace formula.
    double shoelace = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        const auto& [x0, y0] = pts[i];
        const auto& [x1, y1] = pts[(i + 1) % pts.size()];
        shoelace += double(x0) * double(y1) - double(x1) * double(y0);
    }
    // Walk the outline counter-clockwise.
    if (shoelace < 0) std::reverse(pts.begin(), pts.end());
    for (const auto& [x, y] : pts) obj << "v " << x << " " << y << " 0\n";
    obj << "f";
    for (size_t i = 1; i <= pts.size(); ++i) obj << " " << i;
    obj << "\n";
    const fs::path dir = scratch("comb");
    write(dir / "comb.obj", obj.str());
    const LoadedModel m = load_obj(dir / "comb.obj");
    REQUIRE(m.meshes.size() == 1);
    CHECK(m.meshes[0].triangle_count() == pts.size() - 2);
    CHECK(area(m.meshes[0]) == doctest::Approx(std::abs(shoelace) / 2));
    // Every triangle faces +Z like the outline.
    for (size_t t = 0; t < m.meshes[0].triangle_count(); ++t) {
        const auto& p = m.meshes[0].positions;
        const auto* i = &m.meshes[0].indices[3 * t];
        CHECK(cross(p[i[1]] - p[i[0]], p[i[2]] - p[i[0]]).z > 0);
    }
}

TEST_CASE("OBJ normals: given ones are kept, missing ones become flat") {
    const fs::path dir = scratch("normals");
    write(dir / "mixed.obj",
          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvn 0.3 0.3 0.9\n"
          "f 1//1 2//1 3//1\n"  // smooth (file normal)
          "f -5 -4 -1\n");      // no normals, relative indices: (0,0,0) (1,0,0) (0,0,1), normal -Y
    const LoadedModel m = load_obj(dir / "mixed.obj");
    REQUIRE(m.meshes.size() == 1);
    const TriangleMesh& mesh = m.meshes[0];
    REQUIRE(mesh.normals.size() == mesh.positions.size());
    REQUIRE(mesh.triangle_count() == 2);
    const Vec3 given = normalize(Vec3(0.3f, 0.3f, 0.9f));
    for (int k = 0; k < 3; ++k) CHECK(length(mesh.normals[mesh.indices[size_t(k)]] - given) < 1e-6f);
    for (int k = 3; k < 6; ++k) CHECK(length(mesh.normals[mesh.indices[size_t(k)]] - Vec3(0, -1, 0)) < 1e-6f);
    CHECK(mesh.positions[mesh.indices[5]] == Vec3(0, 0, 1));

    write(dir / "plain.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
    CHECK(load_obj(dir / "plain.obj").meshes.at(0).normals.empty());
}

TEST_CASE("OBJ groups and per-face materials, missing .mtl and textures are warnings") {
    const fs::path dir = scratch("groups");
    write(dir / "a.mtl",
          "newmtl red\nKd 1 0 0\nnewmtl tex\nKd 0 1 0\nmap_Kd .\\missing.png\n"
          "newmtl cut\nd 1\nmap_d mask.png\n");
    write(dir / "a.obj",
          "mtllib a.mtl\nmtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
          "g one\nusemtl red\nf 1 2 3\nusemtl tex\nf 1 3 4\n"
          "g two\nusemtl nosuch\nf 1 2 4\n");
    const int warnings_before = warning_count();
    const LoadedModel m = load_obj(dir / "a.obj");
    CHECK(warning_count() - warnings_before >= 3);  // nothere.mtl, missing.png, mask.png (and usemtl nosuch)
    REQUIRE(m.meshes.size() == 2);
    CHECK(m.meshes[0].material_ids == std::vector<uint32_t>{0, 1});
    CHECK(m.materials.size() == 4);  // red, tex, cut, default (for usemtl nosuch)
    CHECK(m.materials[m.meshes[1].material].name == "default");
    CHECK(m.materials[1].albedo.kind == ColorSource::Kind::constant);  // missing texture: Kd stays
    CHECK(m.materials[1].albedo.color == Rgb(0, 1, 0));
    CHECK(m.materials[2].alpha_texture == -1);
    CHECK(m.textures.empty());
}

TEST_CASE("a mirroring world_from_model flips OBJ winding") {
    const fs::path dir = scratch("mirror");
    write(dir / "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const LoadedModel m = load_obj(dir / "t.obj", Mat4::scale({-1, 1, 1}));
    const auto& p = m.meshes.at(0).positions;
    const auto& i = m.meshes.at(0).indices;
    // Front was +Z; mirrored in x it must still be +Z.
    CHECK(cross(p[i[1]] - p[i[0]], p[i[2]] - p[i[0]]).z > 0);
    CHECK(p[i[0]].x <= 0);
}

TEST_CASE("bad OBJ input throws InputError naming file and element") {
    const fs::path dir = scratch("bad");
    CHECK(error_of([&] { load_obj(dir / "none.obj"); }) == (dir / "none.obj").string() + ": no such file");
    fs::create_directories(dir / "folder.obj");
    CHECK(error_of([&] { load_obj(dir / "folder.obj"); }).find("not a regular file") != std::string::npos);

    write(dir / "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    CHECK(error_of([&] { load_obj(dir / "range.obj"); }) ==
          (dir / "range.obj").string() + ": face 2: vertex index out of range (the file has 3)");
    write(dir / "rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
    CHECK(error_of([&] { load_obj(dir / "rel.obj"); }).find("face 1: vertex index out of range") !=
          std::string::npos);
    write(dir / "vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n");
    CHECK(error_of([&] { load_obj(dir / "vt.obj"); }).find("face 1: texture coordinate index out of range") !=
          std::string::npos);

    write(dir / "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(error_of([&] { load_obj(dir / "nan.obj"); }) ==
          (dir / "nan.obj").string() + ": v #2: coordinate is not a finite number");
    write(dir / "inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n");
    CHECK(error_of([&] { load_obj(dir / "inf.obj"); }).find("v #3: coordinate is not a finite number") !=
          std::string::npos);

    write(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    CHECK(error_of([&] { load_obj(dir / "zero.obj"); }).find("zero.obj: malformed OBJ") != std::string::npos);

    write(dir / "empty.obj", "x\nv 0 0 0\n");
    CHECK(error_of([&] { load_obj(dir / "empty.obj"); }) ==
          (dir / "empty.obj").string() + ": no faces (is this an OBJ file?)");

    write(dir / "junk.png", "this is not a png");
    write(dir / "t.mtl", "newmtl m\nmap_Kd junk.png\n");
    write(dir / "tex.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n");
    CHECK(error_of([&] { load_obj(dir / "tex.obj"); }).find("junk.png") != std::string::npos);
}

TEST_CASE("ear clipping handles collinear and repeated vertices") {
    // A square with an extra vertex on one edge and a repeated corner.
    const std::vector<Vec3> poly = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {2, 2, 0}, {0, 2, 0}};
    std::vector<uint32_t> tris;
    triangulate_polygon(poly, tris);
    REQUIRE(tris.size() == 3 * (poly.size() - 2));
    double a = 0;
    for (size_t t = 0; t < tris.size(); t += 3)
        a += 0.5 * double(cross(poly[tris[t + 1]] - poly[tris[t]], poly[tris[t + 2]] - poly[tris[t]]).z);
    CHECK(a == doctest::Approx(4.0));
}

TEST_CASE("OBJ map_d grey masks become alpha, map_Ke textures emission") {
    const fs::path dir = scratch("alpha");
    // A 2x1 single-channel mask: 0 (cut) and 255 (kept).
    const uint8_t px[2] = {0, 255};
    write_image_u8(dir / "mask.png", 2, 1, 1, px);
    write(dir / "m.mtl",
          "newmtl leaf\nKd 0.2 0.8 0.2\nd 1\nmap_d mask.png\n"
          "newmtl lamp\nKe 2 2 2\nmap_Ke mask.png\n");
    write(dir / "m.obj",
          "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf\nf 1 2 3\nusemtl lamp\nf 3 2 1\n");
    const LoadedModel m = load_obj(dir / "m.obj");
    REQUIRE(m.materials.size() == 2);
    const MaterialDesc& leaf = m.materials[0];
    REQUIRE(leaf.alpha_texture >= 0);
    const Image& mask = *m.textures.at(size_t(leaf.alpha_texture)).image;
    CHECK(mask.rgba[3] == 0.0f);  // alpha taken from the grey value, not decoded as sRGB
    CHECK(mask.rgba[7] == 1.0f);
    CHECK(leaf.type == MaterialType::lambertian);
    const MaterialDesc& lamp = m.materials[1];
    CHECK(lamp.type == MaterialType::emissive);
    CHECK(lamp.radiance.kind == ColorSource::Kind::texture);
    CHECK(lamp.radiance.color == Rgb(2, 2, 2));
    CHECK(m.textures.size() == 2);  // the same file as alpha (linear) and as colour (sRGB)
}
