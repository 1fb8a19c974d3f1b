// `sahara view` end to end: the up-axis message and --up, --env with an
// environment image the test writes, and a bad --env file.
#include <doctest/doctest.h>

#include <fstream>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "io/image_io.h"

using namespace sahara;
using sahara::test::CliRun;
using sahara::test::run_sahara;
using sahara::test::TempDir;

namespace {

/// A 2 x 2 x 2 cube centred at z = 5 under a Rhino banner.
void write_rhino_cube(const std::string& file) {
    std::ofstream out(file);
    out << "# Rhino\n\n";
    for (int i = 0; i < 8; ++i)
        out << "v " << (i & 1 ? 1 : -1) << ' ' << (i & 2 ? 1 : -1) << ' ' << (i & 4 ? 6 : 4) << '\n';
    out << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

/// Mean linear RGB of the top row of an image (background only, over the model).
std::vector<double> top_row_mean(const std::string& file) {
    const auto img = read_image(file, false);
    std::vector<double> mean(3, 0.0);
    for (int x = 0; x < img->width; ++x)
        for (int c = 0; c < 3; ++c)
            mean[size_t(c)] += double(img->rgba[size_t(x) * 4 + size_t(c)]) / img->width;
    return mean;
}

}  // namespace

TEST_CASE("view says which up axis it chose and why and --up overrides it") {
    TempDir dir("view_up");
    write_rhino_cube(dir / "cube.obj");
    CliRun r = run_sahara("view cube.obj --size 8 --spp 1 -o a.png", dir);
    REQUIRE(r.code == 0);
    CHECK(r.err.find("up axis +z: the header names rhino") != std::string::npos);
    CHECK(r.err.find("--up x|y|z|-x|-y|-z") != std::string::npos);
    r = run_sahara("view cube.obj --size 8 --spp 1 -o b.png --up=-y", dir);
    REQUIRE(r.code == 0);
    CHECK(r.err.find("up axis") == std::string::npos);
    r = run_sahara("view cube.obj --size 8 --spp 1 -o c.png --up w", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("--up: expected x, y, z, -x, -y or -z") != std::string::npos);
}

TEST_CASE("view --env lights and backs the model with the given image") {
    TempDir dir("view_env");
    write_rhino_cube(dir / "cube.obj");
    // A red environment, 16 x 8, linear float.
    std::vector<float> red(16 * 8 * 3, 0.0f);
    for (size_t i = 0; i < red.size(); i += 3) red[i] = 2.0f;
    write_image(dir / "red.exr", 16, 8, red);
    const std::string common = "view cube.obj --no-ground --size 16 --spp 2 -q ";
    REQUIRE(run_sahara(common + "--env red.exr -o env.exr", dir).code == 0);
    const std::vector<double> env = top_row_mean(dir / "env.exr");
    CHECK(env[0] == doctest::Approx(2.0).epsilon(0.01));
    CHECK(env[1] == doctest::Approx(0.0));
    REQUIRE(run_sahara(common + "--env red.exr --env-strength 0.5 -o half.exr", dir).code == 0);
    CHECK(top_row_mean(dir / "half.exr")[0] == doctest::Approx(1.0).epsilon(0.01));
    // The built-in studio is near-neutral grey.
    REQUIRE(run_sahara(common + "-o studio.exr", dir).code == 0);
    const std::vector<double> studio = top_row_mean(dir / "studio.exr");
    CHECK(studio[1] > 0.1);
    CHECK(studio[0] < 1.3 * studio[1]);
}

TEST_CASE("view --env with a bad file names it and exits 2") {
    TempDir dir("view_env_bad");
    write_rhino_cube(dir / "cube.obj");
    std::ofstream(dir / "broken.exr") << "not an image";
    CliRun r = run_sahara("view cube.obj --size 8 --spp 1 --env broken.exr -o a.png", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("broken.exr") != std::string::npos);
    r = run_sahara("view cube.obj --size 8 --spp 1 --env missing.hdr -o a.png", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("missing.hdr") != std::string::npos);
}
