// The live preview window, headless (SDL's offscreen video driver).
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/preview.h"
#include "cli_test_util.h"
#include "io/image_io.h"
#include "render/tonemap.h"

using namespace sahara;
namespace fs = std::filesystem;

namespace {

/// Reads a binary P6 PPM with maxval 255.
std::vector<unsigned char> read_ppm(const fs::path& file, int* w, int* h) {
    std::ifstream in(file, std::ios::binary);
    std::string magic;
    int maxval = 0;
    in >> magic >> *w >> *h >> maxval;
    in.get();
    REQUIRE(magic == "P6");
    REQUIRE(maxval == 255);
    std::vector<unsigned char> px(size_t(*w) * size_t(*h) * 3);
    in.read(reinterpret_cast<char*>(px.data()), std::streamsize(px.size()));
    REQUIRE(in.good());
    return px;
}

int run_shell(const std::string& cmd) {
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("preview: display bytes are what an 8-bit output file stores") {
    const std::vector<float> rgb = {0.0f, 0.18f, 0.5f, 1.0f, 2.5f, 1e-4f};
    for (Tonemap curve : {Tonemap::clamp, Tonemap::reinhard, Tonemap::aces}) {
        const std::vector<float> mapped = tonemap_image(rgb, 0.5f, curve);
        for (size_t i = 0; i < rgb.size(); i += 3) {
            unsigned char b[3];
            display_bytes(Rgb(rgb[i], rgb[i + 1], rgb[i + 2]), 0.5f, curve, b);
            for (size_t c = 0; c < 3; ++c)
                CHECK(int(b[c]) ==
                      int(std::lround(std::clamp(srgb_encode(mapped[i + c]), 0.0f, 1.0f) * 255.0f)));
        }
    }
}

#if SAHARA_HAVE_SDL2
constexpr bool kHaveSdl2 = true;
#else
constexpr bool kHaveSdl2 = false;
#endif

TEST_CASE("preview: the window's last frame equals the written image (offscreen driver) [needs SDL2]" *
          doctest::skip(!kHaveSdl2)) {
    const sahara::test::TempDir tmp("preview");
    const fs::path& dir = tmp.path;
    const fs::path out = dir / "p.png", dump = dir / "frame.ppm";
    // Leak checking is off for this child only: video drivers keep allocations until exit.
    const std::string cmd = "SDL_VIDEODRIVER=offscreen ASAN_OPTIONS=detect_leaks=0 " +
                            std::string(SAHARA_EXE) +
                            " render --width 40 --height 24 --spp 16 --preview --preview-dump " +
                            dump.string() + " -o " + out.string() + " 2>" + (dir / "err.txt").string();
    const int code = run_shell(cmd);
    CHECK(code == 0);
    REQUIRE(fs::exists(dump));
    int w = 0, h = 0;
    const std::vector<unsigned char> frame = read_ppm(dump, &w, &h);
    CHECK(w == 40);
    CHECK(h == 24);
    const auto img = read_image(out, false);  // 8-bit sRGB values as v / 255
    REQUIRE(img->width == 40);
    size_t mismatches = 0;
    for (size_t i = 0; i < size_t(w) * size_t(h); ++i)
        for (size_t c = 0; c < 3; ++c)
            mismatches += frame[i * 3 + c] != (unsigned char)std::lround(img->rgba[i * 4 + c] * 255.0f);
    CHECK(mismatches == 0);
}

TEST_CASE("preview: without a display the render still runs, with a warning") {
    const sahara::test::TempDir tmp("nodisplay");
    const fs::path& dir = tmp.path;
    const std::string cmd = "env -u DISPLAY -u WAYLAND_DISPLAY -u SDL_VIDEODRIVER " +
                            std::string(SAHARA_EXE) + " render --width 16 --height 8 --spp 2 --preview -o " +
                            (dir / "n.png").string() + " 2>" + (dir / "err.txt").string();
    CHECK(run_shell(cmd) == 0);
    CHECK(fs::exists(dir / "n.png"));
    std::ifstream err(dir / "err.txt");
    const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
    CHECK(text.find("warning: --preview") != std::string::npos);
}
