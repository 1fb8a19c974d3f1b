// End-to-end tests of `sahara render` through the real executable.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/cmd_info.h"
#include "cli_test_util.h"
#include "sanitizer_build.h"
#include "scene/accelerator.h"
#include "app/render_args.h"
#include "geometry/sphere.h"
#include "io/image_io.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

extern char** environ;

using namespace sahara;
namespace fs = std::filesystem;
using namespace sahara::test;

namespace {

/// Starts `sahara args...` without a shell; returns its pid.
pid_t spawn_sahara(const std::vector<std::string>& args, const std::string& err_file) {
    std::vector<std::string> all = {SAHARA_EXE};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = -1;
    REQUIRE(posix_spawn(&pid, SAHARA_EXE, &actions, nullptr, argv.data(), environ) == 0);
    posix_spawn_file_actions_destroy(&actions);
    return pid;
}

/// Waits until the child catches SIGINT (its handler is installed: /proc shows
/// it in SigCgt), so that a signal sent next reaches sahara, not the default action.
void wait_for_sigint_handler(pid_t pid) {
    for (int i = 0; i < 1200; ++i) {
        std::ifstream status("/proc/" + std::to_string(pid) + "/status");
        std::string line;
        while (std::getline(status, line))
            if (line.rfind("SigCgt:", 0) == 0 &&
                (std::stoull(line.substr(7), nullptr, 16) & (1ull << (SIGINT - 1))))
                return;
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    FAIL("sahara never installed its SIGINT handler");
}

int wait_exit_code(pid_t pid) {
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string meta_value(const ImageMetadata& meta, const std::string& key) {
    for (const auto& [k, v] : meta)
        if (k == key) return v;
    return "";
}

std::vector<std::string> files_in(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    return names;
}

const std::string kSmall = " --width 24 --height 16 ";

}  // namespace

TEST_CASE("cli: --help and --version") {
    TempDir dir("help");
    CliRun r = run_sahara("render --help", dir);
    CHECK(r.code == 0);
    CHECK(r.out.find("usage: sahara render") != std::string::npos);
    CHECK(r.out.find("--resume") != std::string::npos);
    r = run_sahara("--version", dir);
    CHECK(r.code == 0);
    CHECK(r.out.find("sahara " SAHARA_VERSION) == 0);
}

TEST_CASE("cli: a bad flag exits 2 with a pointer to the usage") {
    TempDir dir("badflag");
    CliRun r = run_sahara("render --no-such-flag", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("unknown option '--no-such-flag'") != std::string::npos);
    CHECK(r.err.find("(see 'sahara render --help')") != std::string::npos);
    r = run_sahara("render --spp abc", dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("--spp") != std::string::npos);
}

TEST_CASE("cli: a missing output directory exits 2 and writes nothing") {
    TempDir dir("nodir");
    const std::string out = dir / "missing/sub/out.png";
    const CliRun r = run_sahara("render" + kSmall + "--spp 1 -o " + out, dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("does not exist") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("cli: an image too large for the memory exits 2 with a message and writes nothing") {
    // ASan reserves terabytes of address space at start: no address-space limit there.
    if (sahara::test::kSanitized) return;
    TempDir dir("oom");
    const std::string out = dir / "big.png";
    // 32768 x 32768 is in range, but its film needs 36 GiB: more than the 4 GiB allowed here.
    const CliRun r = run_sahara("render --size 32768 --spp 1 -o " + out, dir, "ulimit -v 4000000;");
    CHECK(r.code == 2);
    CHECK(r.err.find("out of memory") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("cli: OpenImageIO is loaded only by commands that read or write an image") {
    // The glibc loader lists every library it opens under LD_DEBUG=files.
    TempDir dir("codec");
    CliRun r = run_sahara("info", dir);  // the default scene has no image textures
    CHECK(r.code == 0);
    r = run_sahara("--version", dir);
    CHECK(r.code == 0);
    const std::string trace = dir / "ld.txt";
    auto loads_oiio = [&](const std::string& args) {
        const std::string cmd = "LD_DEBUG=files LD_DEBUG_OUTPUT=" + trace + " " + std::string(SAHARA_EXE) +
                                " " + args + " >/dev/null 2>&1";
        for (const auto& e : fs::directory_iterator(dir.path))
            if (e.path().filename().string().rfind("ld.txt", 0) == 0) fs::remove(e.path());
        CHECK(std::system(cmd.c_str()) == 0);
        std::string all;
        for (const auto& e : fs::directory_iterator(dir.path))
            if (e.path().filename().string().rfind("ld.txt", 0) == 0) all += read_text(e.path());
        CHECK_FALSE(all.empty());
        return all.find("libOpenImageIO") != std::string::npos;
    };
    CHECK_FALSE(loads_oiio("--version"));
    CHECK_FALSE(loads_oiio("info"));
    CHECK(loads_oiio("render" + kSmall + "--spp 1 -o " + (dir / "out.png")));
}

TEST_CASE("cli: a missing image codec exits 2 before rendering and writes nothing") {
    TempDir dir("nocodec");
    const std::string out = dir / "out.png";
    const std::string cmd = std::string(SAHARA_EXE) + " --image-codec " + (dir / "no-such-codec.so") +
                            " render" + kSmall + "--spp 1 -o " + out + " >/dev/null 2>" + (dir / "err.txt");
    const int status = std::system(cmd.c_str());
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 2);
    const std::string err = read_text(dir / "err.txt");
    CHECK(err.find(out + ": the image codec plugin is missing") != std::string::npos);
    CHECK(err.find("no-such-codec.so") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("cli: the image does not depend on the thread count") {
    TempDir dir("threads");
    REQUIRE(run_sahara("render" + kSmall + "--spp 8 --threads 1 -o " + (dir / "a.png"), dir).code == 0);
    REQUIRE(run_sahara("render" + kSmall + "--spp 8 --threads 2 -o " + (dir / "b.png"), dir).code == 0);
    REQUIRE(run_sahara("render" + kSmall + "--spp 8 --threads 2 -o " + (dir / "c.exr"), dir).code == 0);
    REQUIRE(run_sahara("render" + kSmall + "--spp 8 --threads 1 -o " + (dir / "d.exr"), dir).code == 0);
    // Pixels, not file bytes: the metadata records the (different) render times.
    CHECK(read_image(dir / "a.png", false)->rgba == read_image(dir / "b.png", false)->rgba);
    CHECK(read_image(dir / "c.exr", false)->rgba == read_image(dir / "d.exr", false)->rgba);
}

TEST_CASE("cli: metadata is readable back from PNG and EXR") {
    TempDir dir("meta");
    REQUIRE(run_sahara("render" + kSmall + "--spp 3 --seed 7 -o " + (dir / "m.png"), dir).code == 0);
    REQUIRE(run_sahara("render" + kSmall + "--spp 3 --seed 7 -o " + (dir / "m.exr"), dir).code == 0);
    for (const char* f : {"m.png", "m.exr"}) {
        CAPTURE(f);
        const ImageMetadata meta = read_image_metadata(dir / f);
        CHECK(meta_value(meta, "scene") == "<default>");
        CHECK(meta_value(meta, "spp") == "3");
        CHECK(meta_value(meta, "seed") == "7");
        CHECK(meta_value(meta, "version") == SAHARA_VERSION);
        CHECK(meta_value(meta, "status") == "complete");
        CHECK(std::atof(meta_value(meta, "render_seconds").c_str()) > 0.0);
    }
}

TEST_CASE("cli: 32 spp then --resume to 64 spp equals 64 spp in one run, bit for bit") {
    TempDir dir("resume");
    REQUIRE(run_sahara("render" + kSmall + "--spp 32 -o " + (dir / "half.exr"), dir).code == 0);
    const CliRun r = run_sahara(
        "render" + kSmall + "--spp 64 --resume " + (dir / "half.exr") + " -o " + (dir / "resumed.exr"), dir);
    REQUIRE(r.code == 0);
    REQUIRE(run_sahara("render" + kSmall + "--spp 64 -o " + (dir / "full.exr"), dir).code == 0);
    CHECK(read_image(dir / "resumed.exr", false)->rgba == read_image(dir / "full.exr", false)->rgba);
    CHECK(read_image(dir / "half.exr", false)->rgba != read_image(dir / "full.exr", false)->rgba);
    CHECK(meta_value(read_image_metadata(dir / "resumed.exr"), "spp") == "64");
}

TEST_CASE("cli: --resume refuses a file rendered with other settings") {
    TempDir dir("resume_bad");
    REQUIRE(run_sahara("render" + kSmall + "--spp 2 -o " + (dir / "a.exr"), dir).code == 0);
    CliRun r = run_sahara(
        "render" + kSmall + "--spp 4 --seed 3 --resume " + (dir / "a.exr") + " -o " + (dir / "b.exr"), dir);
    CHECK(r.code == 2);
    CHECK(r.err.find("seed") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "b.exr"));
    REQUIRE(run_sahara("render" + kSmall + "--spp 2 -o " + (dir / "a.png"), dir).code == 0);
    r = run_sahara("render" + kSmall + "--spp 4 --resume " + (dir / "a.png") + " -o " + (dir / "c.exr"), dir);
    CHECK(r.code == 2);
}

TEST_CASE("cli: SIGINT stops, writes the samples done and exits 130") {
    TempDir dir("sigint");
    const std::string out = dir / "long.png";
    const pid_t pid = spawn_sahara(
        {"render", "--width", "24", "--height", "16", "--spp", "1000000", "-o", out}, dir / "err.txt");
    wait_for_sigint_handler(pid);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(pid, SIGINT);
    CHECK(wait_exit_code(pid) == 130);
    REQUIRE(fs::exists(out));
    const ImageMetadata meta = read_image_metadata(out);
    CHECK(meta_value(meta, "status") == "interrupted");
    CHECK(std::atoi(meta_value(meta, "spp").c_str()) < 1000000);
    CHECK(read_image(out, false)->width == 24);
    // A PNG cannot be resumed: the exact state goes to a side file.
    CHECK(fs::exists(out + ".partial.exr"));
    CHECK(read_text(dir / "err.txt").find("interrupted") != std::string::npos);
}

TEST_CASE("cli: a second SIGINT exits at once and leaves no partial file") {
    TempDir dir("sigint2");
    const std::string out = dir / "long.exr";
    const pid_t pid = spawn_sahara(
        {"render", "--width", "24", "--height", "16", "--spp", "1000000", "-o", out}, dir / "err.txt");
    wait_for_sigint_handler(pid);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(pid, SIGINT);
    ::kill(pid, SIGINT);
    CHECK(wait_exit_code(pid) == 130);
    for (const std::string& f : files_in(dir.path)) {
        CAPTURE(f);
        CHECK(f.find(".tmp") == std::string::npos);
        // If the first stop's write finished before the second signal, the file is complete.
        if (f == "long.exr") CHECK(read_image(out, false)->width == 24);
    }
}

TEST_CASE("cli: --time stops early with a valid image") {
    TempDir dir("time");
    const std::string out = dir / "t.exr";
    const CliRun r = run_sahara("render" + kSmall + "--spp 1000000 --time 0.3 -o " + out, dir);
    CHECK(r.code == 0);
    const ImageMetadata meta = read_image_metadata(out);
    CHECK(meta_value(meta, "status") == "time limit");
    CHECK(std::atoi(meta_value(meta, "spp").c_str()) < 1000000);
    CHECK(r.err.find("time limit") != std::string::npos);
}

TEST_CASE("cli: --checkpoint writes the image while the render runs") {
    TempDir dir("checkpoint");
    const std::string out = dir / "c.png";
    const pid_t pid = spawn_sahara(
        {"render", "--width", "24", "--height", "16", "--spp", "1000000", "--checkpoint", "0.2", "-o", out},
        dir / "err.txt");
    wait_for_sigint_handler(pid);
    bool appeared = false;
    for (int i = 0; i < 600 && !appeared; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        appeared = fs::exists(out) && fs::exists(out + ".partial.exr");
    }
    ::kill(pid, SIGTERM);
    CHECK(wait_exit_code(pid) == 130);
    CHECK(appeared);
    CHECK(meta_value(read_image_metadata(out + ".partial.exr"), "version") == SAHARA_VERSION);
}

TEST_CASE("cli: --target-error reports its estimate, --reference the true error") {
    TempDir dir("adaptive");
    REQUIRE(run_sahara("render" + kSmall + "--spp 256 --seed 99 -o " + (dir / "ref.exr"), dir).code == 0);
    const CliRun r = run_sahara("render" + kSmall + "--spp 256 --target-error 0.05 --reference " +
                                    (dir / "ref.exr") + " -o " + (dir / "a.exr"),
                                dir);
    CHECK(r.code == 0);
    CHECK(r.err.find("est. error") != std::string::npos);
    CHECK(r.err.find("true error") != std::string::npos);
    CHECK(!meta_value(read_image_metadata(dir / "a.exr"), "estimated_error").empty());
}

TEST_CASE("cli: --stats prints grouped statistics") {
    TempDir dir("stats");
    const CliRun r = run_sahara("render" + kSmall + "--spp 2 --stats -o " + (dir / "s.png"), dir);
    CHECK(r.code == 0);
    for (const char* s : {"Statistics:", "Render", "Camera rays", "768", "BVH", "Memory", "Time", "Write"})
        CHECK_MESSAGE(r.err.find(s) != std::string::npos, s);
}

TEST_CASE("info: the default scene's contents, memory and times") {
    const nlohmann::json j = scene_info(std::nullopt).to_json();
    CHECK(j["Scene"]["Source"] == "<default>");
    CHECK(j["Objects"]["Spheres"] == 2);
    CHECK(j["Objects"]["Triangles"] == 0);
    CHECK(j["Materials"]["Total"] == 3);
    CHECK(j["Materials"]["lambertian"] == 3);
    CHECK(j["Memory"]["Geometry"] == 2 * sizeof(Sphere));
    CHECK(j["Bounds"]["Max"][1].get<double>() == doctest::Approx(105.0));
    CHECK(j["Time"].contains("Build"));
}

TEST_CASE("info: bad inputs exit 2") {
    CHECK(run_info_command({"--bogus"}) == 2);
    CHECK(run_info_command({"model.xyz"}) == 2);
    CHECK(run_info_command({"a.json", "b.json"}) == 2);
}

TEST_CASE("render --builder overrides the scene's render.bvh_builder") {
    const RenderArgs a = parse_render_args({"--builder", "reinsert"});
    REQUIRE(a.overrides.bvh_builder.has_value());
    RenderSettings r;
    CHECK(r.bvh_builder == kDefaultBvhBuilder);
    a.overrides.apply(r);
    CHECK(r.bvh_builder == BvhBuilder::reinsert);
    RenderSettings untouched;
    untouched.bvh_builder = BvhBuilder::sweep;
    parse_render_args({}).overrides.apply(untouched);
    CHECK(untouched.bvh_builder == BvhBuilder::sweep);
    CHECK_THROWS_AS(parse_render_args({"--builder", "lbvh"}), UsageError);
}

TEST_CASE("render --layout picks the traversal structure the scene's tree is built in") {
    const RenderArgs a = parse_render_args({"--layout", "pairs"});
    REQUIRE(a.overrides.bvh_layout.has_value());
    SceneDesc d = default_scene();
    CHECK(d.render.bvh_layout == BvhLayout::wide8);
    a.overrides.apply(d.render);
    CHECK(d.render.bvh_layout == BvhLayout::pairs);
    const Scene pairs = build_scene(d);
    REQUIRE(pairs.accelerator() != nullptr);
    CHECK(pairs.accelerator()->layout() == BvhLayout::pairs);
    parse_render_args({"--layout", "wide8"}).overrides.apply(d.render);
    CHECK(build_scene(d).accelerator()->layout() == BvhLayout::wide8);
    CHECK(build_scene(default_scene()).accelerator()->layout() == BvhLayout::wide8);
    CHECK_THROWS_AS(parse_render_args({"--layout", "wide16"}), UsageError);
    // The removed layouts are usage errors that name the accepted ones.
    for (const char* removed : {"wide4", "wide4-slots"})
        CHECK_THROWS_WITH_AS(parse_render_args({"--layout", removed}),
                             doctest::Contains("expected wide8|pairs"), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--layout"}), UsageError);
}

TEST_CASE("render --no-packets traces camera rays one by one") {
    RenderSettings r;
    CHECK(r.packets);
    parse_render_args({}).overrides.apply(r);
    CHECK(r.packets);
    parse_render_args({"--no-packets"}).overrides.apply(r);
    CHECK_FALSE(r.packets);
}

TEST_CASE("render flags accept the scene file's ranges, and --size WxH or N") {
    const RenderArgs a =
        parse_render_args({"--seed", "18446744073709551615", "--max-depth", "1024", "--size", "64x32"});
    CHECK(*a.overrides.seed == UINT64_MAX);
    CHECK(*a.overrides.max_depth == 1024);
    CHECK(*a.overrides.width == 64);
    CHECK(*a.overrides.height == 32);
    const RenderArgs square = parse_render_args({"--size", "48", "--spp=3", "-q"});
    CHECK(*square.overrides.width == 48);
    CHECK(*square.overrides.height == 48);
    CHECK(*square.overrides.spp == 3);
    CHECK(square.quiet);
    CHECK_THROWS_AS(parse_render_args({"--seed", "18446744073709551616"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--seed", "-1"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--max-depth", "0"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--max-depth", "1025"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--size", "8x8x8"}), UsageError);
    // A missing or bad side is named, with the value it came from.
    for (const auto& [value, says] :
         {std::pair{"10x", "expected WxH or N, got '10x'"}, std::pair{"x10", "expected WxH or N, got 'x10'"},
          std::pair{"0x10", "the width must be an integer in 1..32768, got '0'"},
          std::pair{"10xq", "the height must be an integer in 1..32768, got 'q'"}}) {
        CAPTURE(value);
        try {
            parse_render_args({"--size", value});
            FAIL("no error");
        } catch (const UsageError& e) {
            CHECK(std::string(e.what()).find(says) != std::string::npos);
        }
    }
    // A repeated option keeps its last value, as before.
    CHECK(*parse_render_args({"--spp", "2", "--spp", "5"}).overrides.spp == 5);
}
