// Usage errors and `sahara --version`, through the real executable.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "accel/simd_path.h"
#include "cli_test_util.h"
#include "app/cmd_version.h"
#include "io/image_codec.h"

namespace fs = std::filesystem;
using namespace sahara::test;

namespace {

/// Checks that `sahara ARGS` fails with exit code 2 and exactly one stderr line
/// naming `culprit` and pointing at `sahara COMMAND --help`.
void check_one_line_usage_error(const std::string& args, const std::string& command,
                                const std::string& culprit) {
    TempDir dir("err");
    const CliRun r = run_sahara(args, dir);
    INFO("sahara " << args << "\nstderr:\n" << r.err);
    CHECK(r.code == 2);
    CHECK(r.out.empty());
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.back() == '\n');
    const std::string program = command.empty() ? "sahara" : "sahara " + command;
    CHECK(r.err.rfind(program + ": ", 0) == 0);
    CHECK(r.err.find(culprit) != std::string::npos);
    CHECK(r.err.find("(see '" + program + " --help')\n") != std::string::npos);
}

}  // namespace

TEST_CASE("cli usage: an unknown option is one line with a help pointer in every command") {
    for (const char* command : {"render", "view", "info", "bvh", "bench", "trace", "converge"}) {
        CAPTURE(command);
        check_one_line_usage_error(std::string(command) + " --bogus", command, "unknown option '--bogus'");
    }
    check_one_line_usage_error("--bogus", "", "unknown option '--bogus'");
    check_one_line_usage_error("frobnicate", "", "unknown command 'frobnicate'");
}

TEST_CASE("cli usage: missing and malformed values are one line too") {
    check_one_line_usage_error("render --spp", "render", "--spp: missing value");
    check_one_line_usage_error("render --spp lots", "render", "'lots'");
    check_one_line_usage_error("render a.json b.json", "render", "more than one scene");
    check_one_line_usage_error("view", "view", "no MODEL given");
    check_one_line_usage_error("view m.obj --up w", "view", "--up");
    check_one_line_usage_error("info a.json b.json", "info", "more than one input");
    check_one_line_usage_error("converge --budget", "converge", "--budget: missing value");
    check_one_line_usage_error("bvh", "bvh", "expected one mesh or scene file");
    check_one_line_usage_error("bvh m.obj --size", "bvh", "--size: missing value");
    check_one_line_usage_error("bench m.obj --ray-set sideways", "bench", "--ray-set: expected");
    check_one_line_usage_error("render --max-depth 0", "render",
                               "--max-depth: expected an integer in 1..1024");
    check_one_line_usage_error("render --threads 0", "render", "--threads: expected an integer in 1..1024");
    check_one_line_usage_error("view m.obj --size 8x", "view", "--size: expected WxH or N, got '8x'");
    check_one_line_usage_error("bvh m.obj --size 0", "bvh", "--size: expected an integer");
    check_one_line_usage_error("--bogus render", "", "unknown option '--bogus'");
    check_one_line_usage_error("trace m.obj", "trace", "--rays and --hits are required");
}

TEST_CASE("cli usage: an option means one thing in every command") {
    // bench's ray-set option was --rays, which in trace names a ray file: the old spelling says the new one.
    check_one_line_usage_error("bench m.obj --rays shadow", "bench", "--rays is now --ray-set");
    // --threads has one range everywhere; bench and bvh take --size as WxH like view.
    for (const char* command : {"render", "converge", "bvh", "bench"}) {
        CAPTURE(command);
        check_one_line_usage_error(std::string(command) + " m.obj --threads 2000", command,
                                   "--threads: expected");
    }
    check_one_line_usage_error("bench m.obj --size 16x", "bench", "--size: expected");
}

TEST_CASE("cli usage: --help still prints the whole text on stdout") {
    TempDir dir("help");
    for (const char* command : {"render", "view", "info", "bvh", "bench", "trace", "converge"}) {
        CAPTURE(command);
        const CliRun r = run_sahara(std::string(command) + " --help", dir);
        CHECK(r.code == 0);
        CHECK(r.out.find(std::string("usage: sahara ") + command) != std::string::npos);
        CHECK(r.err.empty());
    }
}

TEST_CASE("cli: --version names the version and every optional part") {
    TempDir dir("version");
    const CliRun r = run_sahara("--version", dir);
    CHECK(r.code == 0);
    CHECK(r.out.rfind("sahara " SAHARA_VERSION "\n", 0) == 0);
    for (const char* part : {"OpenMP:", "SIMD:", "Embree:", "MPI:", "SDL2:", "image codec:"})
        CHECK(r.out.find(part) != std::string::npos);
    CHECK(r.out.find("sse2 avx2 avx512 compiled in") != std::string::npos);
    CHECK(r.out.find(std::string("this CPU runs ") + sahara::simd_path_name(sahara::best_simd_path())) !=
          std::string::npos);
    // The executable lives in the build tree, with the plugin beside it.
    const fs::path plugin = fs::path(SAHARA_EXE).parent_path() / sahara::kImageCodecLibrary;
    CHECK(r.out.find("OpenImageIO ") != std::string::npos);
    CHECK(r.out.find("plugin " + plugin.string() + "\n") != std::string::npos);
    CHECK(run_sahara("version", dir).out == r.out);
    CHECK(sahara::version_report().rfind("sahara " SAHARA_VERSION "\n", 0) == 0);
}

TEST_CASE("cli: --version reports a missing plugin and a narrowed SIMD path") {
    TempDir dir("version_env");
    const std::string missing = (dir.path / "no-codec.so").string();
    const CliRun r = run_sahara("--image-codec " + missing + " --version", dir, "SAHARA_SIMD=sse2");
    CHECK(r.code == 0);
    CHECK(r.out.find("plugin not found (looked for " + missing + ")") != std::string::npos);
    if (sahara::best_simd_path() != sahara::SimdPath::sse2)
        CHECK(r.out.find("(SAHARA_SIMD selects sse2)") != std::string::npos);
}

TEST_CASE("cli: output lost to a full disk is an error and not exit code 0") {
    if (!fs::exists("/dev/full")) return;
    TempDir dir("full");
    const std::string err = dir / "stderr.txt";
    for (const char* args : {"info --json", "--version"}) {
        CAPTURE(args);
        const std::string cmd = std::string(SAHARA_EXE) + " " + args + " >/dev/full 2>" + err;
        const int status = std::system(cmd.c_str());
        REQUIRE(WIFEXITED(status));
        CHECK(WEXITSTATUS(status) == 2);
        CHECK(read_text(err).find("cannot write to standard output") != std::string::npos);
    }
}
