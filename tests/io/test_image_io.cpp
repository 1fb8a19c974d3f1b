#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "base/error.h"
#include "io/image_io.h"
#include "scratch_dir.h"

using namespace sahara;
namespace fs = std::filesystem;

namespace {

std::vector<float> gradient_pixels(int w, int h) {
    std::vector<float> rgb(size_t(w) * size_t(h) * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &rgb[(size_t(y) * size_t(w) + size_t(x)) * 3];
            p[0] = float(x) / float(w - 1);
            p[1] = float(y) / float(h - 1);
            p[2] = 0.25f;
        }
    return rgb;
}

}  // namespace

TEST_CASE("image round trip: EXR is linear and exact in float") {
    const test::TempDir dir("image_io");
    const fs::path file = dir.path / "round.exr";
    std::vector<float> rgb = gradient_pixels(7, 5);
    rgb[0] = 12.5f;  // HDR values are not clipped
    write_image(file, 7, 5, rgb, {{"spp", "3"}});
    auto img = read_image(file, false);
    REQUIRE(img->width == 7);
    REQUIRE(img->height == 5);
    for (size_t i = 0; i < 35; ++i)
        for (size_t c = 0; c < 3; ++c) CHECK(img->rgba[i * 4 + c] == rgb[i * 3 + c]);
}

TEST_CASE("image round trip: PFM is linear, exact in float and stored bottom row first") {
    const test::TempDir dir("image_io");
    const fs::path file = dir.path / "round.pfm";
    std::vector<float> rgb = gradient_pixels(7, 5);
    rgb[0] = 12.5f;  // top-left red: HDR values are not clipped
    write_image(file, 7, 5, rgb);
    // The file as the format defines it (written by sahara, not OpenImageIO).
    std::ifstream in(file, std::ios::binary);
    std::string header(12, '\0');
    in.read(header.data(), 12);
    CHECK(header == "PF\n7 5\n-1.0\n");
    float first = 0.0f;
    in.read(reinterpret_cast<char*>(&first), sizeof first);
    CHECK(first == rgb[4 * 7 * 3]);  // red of the bottom-left pixel
    in.seekg(0, std::ios::end);
    CHECK(size_t(in.tellg()) == 12 + 7 * 5 * 3 * sizeof(float));
    // And read back through the image reader, top row first again.
    auto img = read_image(file, false);
    REQUIRE(img->width == 7);
    REQUIRE(img->height == 5);
    for (size_t i = 0; i < 35; ++i)
        for (size_t c = 0; c < 3; ++c) CHECK(img->rgba[i * 4 + c] == rgb[i * 3 + c]);
}

TEST_CASE("image round trip: PNG is sRGB-encoded 8-bit") {
    const test::TempDir dir("image_io");
    const fs::path file = dir.path / "round.png";
    const std::vector<float> rgb = gradient_pixels(9, 4);
    write_image(file, 9, 4, rgb);
    auto img = read_image(file, true);
    for (size_t i = 0; i < 36; ++i)
        for (size_t c = 0; c < 3; ++c)
            CHECK(img->rgba[i * 4 + c] == doctest::Approx(rgb[i * 3 + c]).epsilon(0.01));
    // Mid grey 0.5 encodes to sRGB 188/255 (IEC 61966-2-1).
    CHECK(std::lround(srgb_encode(0.5f) * 255) == 188);
    CHECK(srgb_decode(srgb_encode(0.2f)) == doctest::Approx(0.2f));
}

TEST_CASE("image writing is atomic and checks its path first") {
    const test::TempDir tmp("image_io");
    const fs::path& dir = tmp.path;
    CHECK_THROWS_AS(check_output_path(dir / "missing" / "x.png"), InputError);
    CHECK_THROWS_AS(check_output_path(dir / "x.bmpx"), InputError);
    CHECK_NOTHROW(check_output_path(dir / "x.png"));
    write_image(dir / "a.png", 2, 2, std::vector<float>(12, 0.5f));
    // Nothing but the finished file is left in the directory.
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.path().filename().string().find(".tmp") != std::string::npos;
    CHECK(files == 0);
}

TEST_CASE("an output name that is a directory or under a file is refused with the reason") {
    const test::TempDir tmp("image_io");
    const fs::path& dir = tmp.path;
    fs::create_directory(dir / "taken.png");
    std::ofstream(dir / "plain.txt") << "x";
    CHECK_THROWS_WITH(check_output_path(dir / "taken.png"), doctest::Contains("is a directory"));
    CHECK_THROWS_WITH(check_output_path(dir / "plain.txt" / "x.png"),
                      doctest::Contains("is not a directory"));
    // Written anyway, the rename fails; the message gives its real reason.
    try {
        write_image(dir / "taken.png", 2, 2, std::vector<float>(12, 0.5f));
        FAIL("writing onto a directory succeeded");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("Success") == std::string::npos);
    }
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.path().filename().string().find(".tmp") != std::string::npos;
    CHECK(files == 0);
}

TEST_CASE("reading a missing or broken image names the file") {
    const test::TempDir tmp("image_io");
    const fs::path& dir = tmp.path;
    CHECK_THROWS_WITH_AS(read_image(dir / "nope.png", true), doctest::Contains("nope.png"), InputError);
    { std::ofstream(dir / "broken.png") << "not a png"; }
    CHECK_THROWS_WITH_AS(read_image(dir / "broken.png", true), doctest::Contains("broken.png"), InputError);
}
