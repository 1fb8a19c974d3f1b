// OBJ/MTL into sahara's materials (pbr where the MTL asks for it), and the text
// quirks of downloaded OBJ files: malformed numbers, UTF-16/32, quad splits.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "base/error.h"
#include "io/image_io.h"
#include "io/model_loader.h"
#include "error_message.h"
#include "scratch_dir.h"

using namespace sahara;
using sahara::test::error_of;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return test::scratch_dir("objmat_" + name); }

void write(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

/// What `f` writes to stderr (the warnings of base/log), by redirecting file descriptor 2.
template <class F>
std::string stderr_of(const fs::path& dir, F&& f) {
    const fs::path file = dir / "stderr.txt";
    std::fflush(stderr);
    const int saved = dup(2);
    const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 2);
    close(fd);
    f();
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

const char* kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";

/// Loads an OBJ whose one triangle uses each material of `mtl` in turn.
LoadedModel load_with_mtl(const fs::path& dir, const std::string& mtl,
                          const std::vector<std::string>& names) {
    write(dir / "m.mtl", mtl);
    std::string obj = std::string("mtllib m.mtl\n") + kTriangleObj;
    for (const std::string& n : names) obj += "usemtl " + n + "\nf 1/1 2/2 3/3\n";
    write(dir / "m.obj", obj);
    return load_obj(dir / "m.obj");
}

const MaterialDesc& named(const LoadedModel& m, const std::string& name) {
    for (const MaterialDesc& d : m.materials)
        if (d.name == name) return d;
    FAIL("no material " << name);
    return m.materials.front();
}

}  // namespace

TEST_CASE("MTL classic specular and the MTL PBR extension become pbr materials") {
    const fs::path dir = scratch("pbr");
    const LoadedModel m =
        load_with_mtl(dir,
                      "newmtl matte\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 500\nillum 1\n"
                      "newmtl glossy\nKd 0.5 0.25 0.5\nKs 0.5 0.5 0.5\nNs 98\nillum 2\nNi 1.45\n"
                      "newmtl chrome\nKd 0 0 0\nKs 0.9 0.8 0.7\nNs 998\nillum 3\n"
                      "newmtl ext\nKd 1 0 0\nPr 0.3\nPm 0.7\nTr 0.25\nNi 1.0\n",
                      {"matte", "glossy", "chrome", "ext"});
    const MaterialDesc& matte = named(m, "matte");
    CHECK(matte.type == MaterialType::lambertian);  // illum 1: no specular highlight
    const MaterialDesc& glossy = named(m, "glossy");
    CHECK(glossy.type == MaterialType::pbr);
    CHECK(glossy.albedo.color == Rgb(0.5f, 0.25f, 0.5f));
    CHECK(glossy.metallic == 0.0f);
    CHECK(glossy.roughness == doctest::Approx(std::pow(2.0 / 100.0, 0.25)));  // (2 / (Ns + 2))^(1/4)
    CHECK(glossy.ior == doctest::Approx(1.45f));
    const MaterialDesc& chrome = named(m, "chrome");
    CHECK(chrome.metallic == 1.0f);  // black Kd with a specular colour
    CHECK(chrome.albedo.color == Rgb(0.9f, 0.8f, 0.7f));
    CHECK(chrome.roughness == doctest::Approx(std::pow(2.0 / 1000.0, 0.25)));
    const MaterialDesc& ext = named(m, "ext");
    CHECK(ext.type == MaterialType::pbr);
    CHECK(ext.roughness == doctest::Approx(0.3f));
    CHECK(ext.metallic == doctest::Approx(0.7f));
    CHECK(ext.alpha == doctest::Approx(0.75f));  // Tr = 1 - d
    CHECK(ext.ior == 1.5f);                      // Ni 1 (a common exporter default) is no ior
}

TEST_CASE("MTL textures: map_Pr and map_Pm packed and norm and map_Bump and map_Ke with map_Kd") {
    const fs::path dir = scratch("maps");
    const uint8_t grey64 = 64, white[4] = {255, 255, 255, 255}, normal[3] = {128, 128, 255};
    write_image_u8(dir / "rough.png", 1, 1, 1, &grey64);
    write_image_u8(dir / "metal.png", 2, 2, 1, white);
    write_image_u8(dir / "n.png", 1, 1, 3, normal);
    const uint8_t ramp[9] = {0, 100, 200, 0, 100, 200, 0, 100, 200};  // height rising to the right
    write_image_u8(dir / "height.png", 3, 3, 1, ramp);
    write_image_u8(dir / "c.png", 1, 1, 3, normal);
    const LoadedModel m = load_with_mtl(dir,
                                        "newmtl packed\nKd 1 1 1\nmap_Pr rough.png\nmap_Pm metal.png\n"
                                        "norm -bm 0.5 n.png\n"
                                        "newmtl bumpy\nKd 1 1 1\nmap_Bump height.png\n"
                                        "newmtl normalbump\nKd 1 1 1\nbump n.png\n"
                                        "newmtl glow\nKd 1 1 1\nmap_Kd c.png\nKe 1 0.5 0\n",
                                        {"packed", "bumpy", "normalbump", "glow"});
    const MaterialDesc& packed = named(m, "packed");
    REQUIRE(packed.metallic_roughness_texture >= 0);
    const Image& mr = *m.textures[size_t(packed.metallic_roughness_texture)].image;
    CHECK(mr.width == 2);                               // the larger of the two maps
    CHECK(mr.rgba[1] == doctest::Approx(64 / 255.0f));  // G: roughness, linear
    CHECK(mr.rgba[2] == 1.0f);                          // B: metallic
    CHECK(packed.roughness == 1.0f);                    // the maps replace the numbers
    CHECK(packed.metallic == 1.0f);
    REQUIRE(packed.normal_texture >= 0);
    CHECK(packed.normal_scale == 0.5f);

    const MaterialDesc& bumpy = named(m, "bumpy");
    REQUIRE(bumpy.normal_texture >= 0);
    const Image& bn = *m.textures[size_t(bumpy.normal_texture)].image;
    const float* centre = &bn.rgba[4 * 4];
    // Full range = a relief 1/64 of the width deep: slope = (200/255) * (3 / 64) / 2 per texel pair.
    const float slope = 200 / 255.0f * 3.0f / 64.0f / 2.0f;
    CHECK(centre[0] == doctest::Approx(0.5f - 0.5f * slope / std::sqrt(1 + slope * slope)));  // leans left
    CHECK(centre[1] == doctest::Approx(0.5f));  // flat vertically
    CHECK(centre[2] > 0.99f);
    const MaterialDesc& normalbump = named(m, "normalbump");
    REQUIRE(normalbump.normal_texture >= 0);
    CHECK(m.textures[size_t(normalbump.normal_texture)].image->rgba[0] == doctest::Approx(128 / 255.0f));

    const MaterialDesc& glow = named(m, "glow");
    CHECK(glow.type == MaterialType::pbr);  // a textured surface with glowing parts, not emissive only
    CHECK(glow.albedo.kind == ColorSource::Kind::texture);
    CHECK(glow.radiance.color == Rgb(1, 0.5f, 0));
}

TEST_CASE("OBJ and MTL malformed numbers warn with file and line") {
    const fs::path dir = scratch("numbers");
    write(dir / "n.mtl", "newmtl a\nKd 0.5 0,5 0.5\n");
    write(dir / "n.obj", "mtllib n.mtl\nv 0 0 0\nv 3.1+e2 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    LoadedModel m;
    const std::string err = stderr_of(dir, [&] { m = load_obj(dir / "n.obj"); });
    CHECK(err.find((dir / "n.obj").string() + ": line 3: malformed number '3.1+e2', read as 3.1") !=
          std::string::npos);
    CHECK(err.find((dir / "n.mtl").string() + ": line 2: malformed number '0,5'") != std::string::npos);
    CHECK(m.meshes.at(0).positions[1].x == doctest::Approx(3.1f));  // as tinyobjloader reads it
    // Well-formed numbers in every notation stay silent.
    write(dir / "ok.obj", "v 0 0 0\nv 1e0 +0 -0.0\nv .0 1. 0E+0\nf 1 2 3\n");
    CHECK(stderr_of(dir, [&] { load_obj(dir / "ok.obj"); }).find("malformed") == std::string::npos);
}

TEST_CASE("UTF-16 and UTF-32 OBJ files are named as such") {
    const fs::path dir = scratch("utf");
    auto with_bom = [&](const std::string& bom, const char* name) {
        std::string text = bom;
        for (char c : std::string("v 0 0 0\n")) text += std::string(1, c) + std::string(1, '\0');
        write(dir / name, text);
        return error_of([&] { load_obj(dir / name); });
    };
    CHECK(with_bom("\xFF\xFE", "le16.obj").find("le16.obj: is UTF-16 (little-endian) text") !=
          std::string::npos);
    CHECK(with_bom("\xFE\xFF", "be16.obj").find("is UTF-16 (big-endian) text") != std::string::npos);
    CHECK(with_bom(std::string("\xFF\xFE\0\0", 4), "le32.obj").find("is UTF-32 (little-endian)") !=
          std::string::npos);
    // A UTF-8 byte-order mark is harmless.
    write(dir / "bom8.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(load_obj(dir / "bom8.obj").meshes.size() == 1);
}

TEST_CASE("a convex quad splits along its v0-v2 diagonal") {
    const fs::path dir = scratch("quad");
    // Non-planar: v2 is lifted, so the diagonal decides the shape.
    write(dir / "q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 1\nv 0 1 0\nf 1 2 3 4\n");
    const LoadedModel m = load_obj(dir / "q.obj");
    const TriangleMesh& mesh = m.meshes.at(0);
    REQUIRE(mesh.triangle_count() == 2);
    for (size_t t = 0; t < 2; ++t) {
        int corners = 0;
        for (size_t k = 0; k < 3; ++k) {
            const Vec3& p = mesh.positions[mesh.indices[3 * t + k]];
            corners += (p == Vec3(0, 0, 0) || p == Vec3(1, 1, 1)) ? 1 : 0;
        }
        CHECK(corners == 2);  // both triangles hold v0 and v2
    }
}
