// Distributed rendering (MPI) and frame sequences. The end-to-end cases run
// the real executable under mpirun on localhost; they are skipped — loudly —
// only when this build has no MPI (CI installs it, so there they run).
// OpenMPI's own allocations look like leaks to LeakSanitizer, so the ranks run
// with ASAN_OPTIONS=detect_leaks=0 (exported by mpirun -x); everything else
// about the sanitizers stays on.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/mpi_session.h"
#include "cli_test_util.h"
#include "app/mpi_work.h"
#include "app/render_args.h"
#include "io/image_io.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "io/scene_parser.h"

extern char** environ;

using namespace sahara;
namespace fs = std::filesystem;
using namespace sahara::test;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr int kSlow = 4;  // sanitizers: fewer samples, same code paths
#else
constexpr int kSlow = 1;
#endif

std::string meta_value(const std::string& file, const std::string& key) {
    for (const auto& [k, v] : read_image_metadata(file))
        if (k == key) return v;
    return "";
}

/// A shell command in its own process group, so a timeout can end mpirun and its ranks.
struct Job {
    pid_t pid = -1;
    explicit Job(const std::string& command) {
        posix_spawnattr_t attr;
        posix_spawnattr_init(&attr);
        posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
        posix_spawnattr_setpgroup(&attr, 0);
        std::string cmd = command;
        char sh[] = "/bin/sh", c[] = "-c";
        char* argv[] = {sh, c, cmd.data(), nullptr};
        REQUIRE(posix_spawn(&pid, "/bin/sh", nullptr, &attr, argv, environ) == 0);
        posix_spawnattr_destroy(&attr);
    }
    bool running() const { return ::kill(pid, 0) == 0 && !exited_; }
    /// Exit code, or -1 if it did not end within `seconds` (then the group is killed).
    int wait(double seconds) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
        while (std::chrono::steady_clock::now() < end) {
            int status = 0;
            if (waitpid(pid, &status, WNOHANG) == pid) {
                exited_ = true;
                return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        ::kill(-pid, SIGKILL);
        waitpid(pid, nullptr, 0);
        exited_ = true;
        return -1;
    }
    bool exited_ = false;
};

/// The mpirun command that starts `ranks` ranks of what follows (MPI builds only).
std::string mpirun(int ranks, const std::string& extra = "") {
#if SAHARA_HAVE_MPI
    return "ASAN_OPTIONS=detect_leaks=0 " SAHARA_MPIEXEC
           " --allow-run-as-root --oversubscribe --bind-to none --mca btl_vader_single_copy_mechanism none"
           " -x ASAN_OPTIONS " +
           extra + " -np " + std::to_string(ranks) + " ";
#else
    (void)extra;
    FAIL("mpirun with " << ranks << " ranks in a build without MPI");
    return "";
#endif
}

/// Runs `sahara ARGS` (through mpirun with `ranks` ranks when ranks > 0); exit code.
int run(const std::string& args, int ranks, const std::string& err_file, double timeout = 120) {
    const std::string cmd = (ranks > 0 ? mpirun(ranks) : "") + SAHARA_EXE + " " + args + " 2>" + err_file;
    Job job(cmd);
    const int code = job.wait(timeout);
    if (code != 0) MESSAGE("`" << cmd << "` exited " << code << ":\n" << read_text(err_file));
    return code;
}

const std::vector<std::string> kStateChannels = {
    "sahara_state.sum_r_hi", "sahara_state.sum_r_lo", "sahara_state.sum_g_hi",
    "sahara_state.sum_g_lo", "sahara_state.sum_b_hi", "sahara_state.sum_b_lo",
    "sahara_state.sumsq_hi", "sahara_state.sumsq_lo", "sahara_state.count"};

/// Decoded pixels and the exact film state (per-pixel double sums, counts) are equal.
void check_same_render(const std::string& a, const std::string& b) {
    INFO(a << " vs " << b);
    REQUIRE(fs::exists(a));
    REQUIRE(fs::exists(b));
    CHECK(read_image(a, false)->rgba == read_image(b, false)->rgba);
    int wa = 0, ha = 0, wb = 0, hb = 0;
    const auto sa = read_extra_channels(a, kStateChannels, &wa, &ha);
    const auto sb = read_extra_channels(b, kStateChannels, &wb, &hb);
    REQUIRE(wa == wb);
    REQUIRE(ha == hb);
    for (size_t c = 0; c < kStateChannels.size(); ++c)
        CHECK_MESSAGE(sa[c].values == sb[c].values, kStateChannels[c]);
}

/// mpirun tests need an MPI build: without one they are reported as skipped (test_main.cpp).
#if SAHARA_HAVE_MPI
constexpr bool kHaveMpi = true;
#else
constexpr bool kHaveMpi = false;
#endif

const std::string kWorkshop = std::string(SAHARA_SOURCE_DIR) + "/scenes/workshop.json";

}  // namespace

TEST_CASE("frames: output names") {
    CHECK(frame_output_name("out_####.png", 7) == "out_0007.png");
    CHECK(frame_output_name("out_#.exr", 123) == "out_123.exr");
    CHECK(frame_output_name("a/f%04d.exr", 12) == "a/f0012.exr");
    CHECK(frame_output_name("f%d.png", 5) == "f5.png");
    CHECK(frame_output_name("100%_f%03d.png", 5) == "100%_f005.png");
    CHECK_THROWS_AS(frame_output_name("plain.png", 1), UsageError);
}

TEST_CASE("frames: --frames parsing") {
    RenderArgs a = parse_render_args({"--frames", "3..5", "-o", "f_##.png"});
    REQUIRE(a.frames);
    CHECK(a.frames->first == 3);
    CHECK(a.frames->second == 5);
    a = parse_render_args({"--frames", "4", "-o", "f_##.png"});
    CHECK(a.frames->first == 4);
    CHECK(a.frames->second == 4);
    CHECK_THROWS_AS(parse_render_args({"--frames", "5..3", "-o", "f_#.png"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--frames", "1..2", "-o", "plain.png"}), UsageError);
    CHECK_THROWS_AS(parse_render_args({"--frames", "1..2", "-o", "f#.exr", "--resume", "x.exr"}), UsageError);
}

TEST_CASE("mpi: a plain run is not an MPI launch") {
    // The test runner is not started by mpirun: rendering must not initialise MPI.
    if (!launched_by_mpi()) {
        const MpiSession mpi;
        CHECK(mpi.size() == 1);
        CHECK_FALSE(mpi.distributed());
        CHECK(mpi.broadcast("x") == "x");
        CHECK(mpi.all_ok(true));
    }
}

TEST_CASE("mpi: a tile rendered as units through the wire format equals the single-process film") {
    SceneDesc desc = parse_scene_file(kWorkshop);
    desc.render.width = 40;
    desc.render.height = 24;
    desc.render.spp = 12;
    const Scene scene = build_scene(desc);
    Film whole(40, 24);
    RenderOptions options;
    options.threads = 2;
    render_image(scene, whole, options);

    // Tile (16..32, 16..24), taken in two units (5 then 12 spp) that cross the wire.
    const Camera camera(scene.camera, 40, 24);
    mpi_work::TileWork w;
    w.tile = 7;
    w.rect = {16, 16, 32, 24};
    w.state.resize(w.pixels());
    std::atomic<bool> stop{false};
    for (uint32_t target : {5u, 12u}) {
        w.targets.assign(w.pixels(), target);
        mpi_work::TileWork sent = mpi_work::decode_work(mpi_work::encode_work(w));
        CHECK(sent.tile == 7);
        mpi_work::render_work(scene, camera, sent, stop);
        mpi_work::TileWork back;
        back.rect = w.rect;
        mpi_work::decode_result(mpi_work::encode_result(sent), back);
        CHECK(back.samples == uint64_t(w.pixels()) * (target == 5 ? 5 : 7));
        w.state = back.state;
    }
    bool same = true;
    for (int y = 16; y < 24; ++y)
        for (int x = 16; x < 32; ++x) {
            const mpi_work::PixelState& p = w.state[size_t(y - 16) * 16 + size_t(x - 16)];
            same = same && p.count == whole.count(x, y) && p.sum_sq == whole.sum_sq(x, y) &&
                   p.sum.x == whole.sum(x, y).x && p.sum.y == whole.sum(x, y).y &&
                   p.sum.z == whole.sum(x, y).z;
        }
    CHECK(same);
    // A truncated message is refused, not read past its end.
    std::vector<char> bytes = mpi_work::encode_work(w);
    bytes.resize(bytes.size() - 3);
    CHECK_THROWS(mpi_work::decode_work(bytes));
}

TEST_CASE("mpi: 2 and 3 ranks render bit-identical to one process (uniform and adaptive) [needs MPI]" *
          doctest::skip(!kHaveMpi)) {
    TempDir dir("identical");
    const std::string err = dir / "err.txt";
    const std::string common = kWorkshop + " --width 72 --height 40 --threads 1 --quiet ";
    const std::string uniform = common + "--spp " + std::to_string(32 / kSlow);
    REQUIRE(run("render " + uniform + " -o " + (dir / "one.exr"), 0, err) == 0);
    REQUIRE(run("render " + uniform + " -o " + (dir / "two.exr"), 2, err) == 0);
    REQUIRE(run("render " + uniform + " -o " + (dir / "three.exr"), 3, err) == 0);
    check_same_render(dir / "one.exr", dir / "two.exr");
    check_same_render(dir / "one.exr", dir / "three.exr");
    // Adaptive rounds see the whole film between rounds, as in one process.
    const std::string adaptive = common + "--spp 256 --target-error 0.05";
    REQUIRE(run("render " + adaptive + " -o " + (dir / "a1.exr"), 0, err) == 0);
    REQUIRE(run("render " + adaptive + " -o " + (dir / "a3.exr"), 3, err) == 0);
    check_same_render(dir / "a1.exr", dir / "a3.exr");
    CHECK(meta_value(dir / "a3.exr", "status") == "converged");
}

TEST_CASE(
    "mpi: a rank killed mid-render ends the job, and the checkpoint resumes to the one-go image [needs MPI]" *
    doctest::skip(!kHaveMpi)) {
    TempDir dir("killed");
    const std::string args = "render " + kWorkshop + " --width 128 --height 96 --threads 1 --spp " +
                             std::to_string(512 / kSlow) + " ";
    const std::string err = dir / "err.txt";
    const std::string cmd = "SAHARA_MPI_PID_DIR=" + dir.path.string() + " " +
                            mpirun(2, "-x SAHARA_MPI_PID_DIR") + SAHARA_EXE + " " + args +
                            "--checkpoint 0.3 -o " + (dir / "k.exr") + " 2>" + err;
    Job job(cmd);
    // Wait for a checkpoint, then kill rank 1 while the render is still going.
    for (int i = 0; i < 3000 && !(fs::exists(dir / "k.exr") && fs::exists(dir / "rank-1.pid")); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    REQUIRE(fs::exists(dir / "k.exr"));
    REQUIRE_MESSAGE(job.running(), "the render ended before the kill; make it longer");
    const pid_t rank1 = pid_t(std::stoi(read_text(dir / "rank-1.pid")));
    REQUIRE(::kill(rank1, SIGKILL) == 0);
    const int code = job.wait(60);
    REQUIRE_MESSAGE(code != -1, "the job hung after a rank died");
    CHECK(code != 0);
    const std::string log = read_text(err);
    INFO(log);
    CHECK(log.find("rank 1") != std::string::npos);  // mpirun's report, or rank 0's warning
    CHECK(meta_value(dir / "k.exr", "status") == "interrupted");

    // Resume the checkpoint (across 2 ranks again) and compare with one uninterrupted process.
    REQUIRE(run(args + "--quiet --resume " + (dir / "k.exr") + " -o " + (dir / "resumed.exr"), 2, err) == 0);
    REQUIRE(run(args + "--quiet --threads 2 -o " + (dir / "one.exr"), 0, err) == 0);
    check_same_render(dir / "one.exr", dir / "resumed.exr");
}

namespace {

const std::string kFramesArgs = "render " + std::string(SAHARA_SOURCE_DIR) +
                                "/scenes/materials.json --width 48 --height 32 --spp 8 --quiet ";

}  // namespace

TEST_CASE("frames: --frames renders a sequence, moving objects move") {
    TempDir dir("frames");
    const std::string err = dir / "err.txt";
    REQUIRE(run(kFramesArgs + "--frames 0..2 -o " + (dir / "seq_##.exr"), 0, err) == 0);
    for (const char* f : {"seq_00.exr", "seq_01.exr", "seq_02.exr"}) CHECK(fs::exists(dir / f));
    CHECK_FALSE(fs::exists(dir / "seq_03.exr"));
    // Frame 0 is the plain render; frame 1 sees the moving sphere elsewhere.
    REQUIRE(run(kFramesArgs + "-o " + (dir / "plain.exr"), 0, err) == 0);
    check_same_render(dir / "plain.exr", dir / "seq_00.exr");
    CHECK(read_image(dir / "seq_00.exr", false)->rgba != read_image(dir / "seq_01.exr", false)->rgba);
}

TEST_CASE("frames: ranks take whole frames, each as one process renders it [needs MPI]" *
          doctest::skip(!kHaveMpi)) {
    TempDir dir("frames_mpi");
    const std::string err = dir / "err.txt";
    REQUIRE(run(kFramesArgs + "--frames 0..2 -o " + (dir / "seq_##.exr"), 0, err) == 0);
    REQUIRE(run(kFramesArgs + "--frames 0..2 -o " + (dir / "mpi_%02d.exr"), 2, err) == 0);
    for (const char* f : {"00", "01", "02"})
        check_same_render(dir / ("seq_" + std::string(f) + ".exr"), dir / ("mpi_" + std::string(f) + ".exr"));
}
