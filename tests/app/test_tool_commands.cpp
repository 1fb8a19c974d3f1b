// The BVH tool commands (trace, bvh, bench) and sahara against Embree; the
// library's BVH tests are tests/accel/test_bvh.cpp.
#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "pipeline/bench_rays.h"
#include "app/commands.h"
#include "app/ray_batch.h"
#include "cli_test_util.h"
#include "mesh_fixtures.h"
#include "scene/accelerator.h"
#include "test_data.h"

using namespace sahara;
using namespace sahara::test;

namespace {

/// Runs a command with stdout captured into a string (via a temporary file).
template <class Fn>
std::pair<int, std::string> run_captured(Fn fn, std::vector<std::string> args) {
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    const auto path =
        std::filesystem::temp_directory_path() / ("sahara_capture_" + std::to_string(::getpid()));
    std::fflush(stdout);
    const int saved = ::dup(1);
    std::FILE* f = std::fopen(path.string().c_str(), "w");
    ::dup2(::fileno(f), 1);
    const int code = fn(int(argv.size()), argv.data());
    std::fflush(stdout);
    ::dup2(saved, 1);
    ::close(saved);
    std::fclose(f);
    std::ifstream in(path);
    std::string out((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(path);
    return {code, out};
}

void write_file(const std::filesystem::path& p, const void* data, size_t bytes) {
    std::ofstream out(p, std::ios::binary);
    out.write(static_cast<const char*>(data), std::streamsize(bytes));
}

}  // namespace

TEST_CASE("sahara agrees with Embree on real and scan-like meshes (bench ray sets) [needs Embree]" *
          doctest::skip(!EmbreeReference::available())) {
    const int side = kSanitized ? 48 : 128;
    for (const TriangleMesh& mesh : realistic_meshes()) {
        Scene scene = scene_from_mesh(mesh);
        const Accelerator acc(scene);
        const EmbreeReference embree(mesh.positions, mesh.indices);
        const BenchRaySets sets = make_bench_rays(scene, acc, side, side);
        for (int s = 0; s < 3; ++s) {
            const std::vector<Ray>& rays = s == 0 ? sets.primary : s == 1 ? sets.diffuse : sets.shadow;
            RayAnswers a, b;
            trace_sahara(acc, rays, s == 2, 2, true, a);
            trace_embree(embree, rays, s == 2, 2, true, b);
            const Disagreements d = compare_answers(a, b, rays, mesh);
            INFO(mesh.name, " set ", s, " ties ", d.ties, " confirmed for sahara ", d.confirmed_for_a);
            CHECK(d.total == 0);
            CHECK(a.hits() > 0);
        }
    }
}

TEST_CASE("compare_answers counts hit/miss, t and primitive differences") {
    TriangleMesh mesh = make_icosphere(1);
    std::vector<Ray> rays(4, Ray{{0, 0, 5}, {0, 0, -1}});
    RayAnswers a{{4.0f, kInfinity, 4.0f, 4.0f}, {1, kNoPrim, 2, 3}};
    RayAnswers b{{4.0f, 4.0f, 4.5f, 4.0f}, {1, 7, 2, 9}};
    const Disagreements d = compare_answers(a, b, rays, mesh);
    // ray 1: b hits, a misses, but double precision says the ray hits the sphere: not for a.
    // ray 2: t differs by 12%; ray 3: another primitive at the same t is a tie.
    CHECK(d.ties == 1);
    CHECK(d.total + d.confirmed_for_a == 2);
    CHECK(d.total >= 1);
}

TEST_CASE("trace command: hits, occlusion, fan-split indices and bad input") {
    const TempDir tmp("trace");
    const std::filesystem::path& dir = tmp.path;
    const auto obj = dir / "quad.obj", rays_file = dir / "in.rays", hits = dir / "out.hits",
               occl = dir / "out.occl";
    {
        std::ofstream o(obj);
        o << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 5 5 5\nf 1 2 3 4\n";  // degenerate first: index
                                                                                   // 0
    }
    const float rays[3][8] = {{0.8f, 0.2f, 1, 0, 0, -1, 0, 100},   // triangle (v0,v1,v2) = index 1
                              {0.2f, 0.8f, 1, 0, 0, -1, 0, 100},   // triangle (v0,v2,v3) = index 2
                              {3.0f, 3.0f, 1, 0, 0, -1, 0, 100}};  // miss
    write_file(rays_file, rays, sizeof(rays));
    auto run = [&](std::vector<std::string> args) {
        return run_captured(run_trace_command, std::move(args)).first;
    };
    REQUIRE(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", hits.string(), "--occlusion",
                 occl.string()}) == 0);
    std::ifstream h(hits, std::ios::binary);
    const std::vector<char> hb((std::istreambuf_iterator<char>(h)), std::istreambuf_iterator<char>());
    REQUIRE(hb.size() == 24);
    float t[3];
    uint32_t prim[3];
    for (int i = 0; i < 3; ++i) {
        std::memcpy(&t[i], &hb[size_t(8 * i)], 4);
        std::memcpy(&prim[i], &hb[size_t(8 * i + 4)], 4);
    }
    CHECK(t[0] == doctest::Approx(1.0f));
    CHECK(prim[0] == 1);
    CHECK(prim[1] == 2);
    CHECK(std::isinf(t[2]));
    CHECK(prim[2] == kNoPrim);
    std::ifstream oc(occl, std::ios::binary);
    const std::vector<char> ob((std::istreambuf_iterator<char>(oc)), std::istreambuf_iterator<char>());
    CHECK(ob == std::vector<char>{1, 1, 0});
    // Bad input: exit 2, and no output left behind.
    const auto out2 = dir / "bad.hits";
    write_file(dir / "short.rays", rays, 33);
    CHECK(run({"trace", obj.string(), "--rays", (dir / "short.rays").string(), "--hits", out2.string()}) ==
          2);
    float nan_ray[8] = {0, 0, 1, 0, 0, -1, 0, std::nanf("")};
    write_file(dir / "nan.rays", nan_ray, sizeof(nan_ray));
    CHECK(run({"trace", obj.string(), "--rays", (dir / "nan.rays").string(), "--hits", out2.string()}) == 2);
    CHECK(run({"trace", (dir / "missing.obj").string(), "--rays", rays_file.string(), "--hits",
               out2.string()}) == 2);
    CHECK(run({"trace", obj.string(), "--rays", (dir / "missing.rays").string(), "--hits", out2.string()}) ==
          2);
    CHECK(!std::filesystem::exists(out2));
    // An output naming an input file is refused, and the input stays as it was.
    const auto rays_size = std::filesystem::file_size(rays_file);
    CHECK(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", rays_file.string()}) == 2);
    CHECK(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", out2.string(), "--occlusion",
               (dir / "." / "in.rays").string()}) == 2);
    CHECK(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", obj.string()}) == 2);
    CHECK(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", out2.string(), "--occlusion",
               out2.string()}) == 2);
    CHECK(std::filesystem::file_size(rays_file) == rays_size);
    CHECK(!std::filesystem::exists(out2));
    CHECK(run({"trace", obj.string(), "--hits", out2.string()}) == 2);
    CHECK(run({"trace", obj.string(), "--rays", rays_file.string(), "--hits", out2.string(), "--bogus"}) ==
          2);
    const auto help = run_captured(run_trace_command, {"trace", "--help"});
    CHECK(help.first == 0);
    CHECK(help.second.find("fan-split") != std::string::npos);
    std::filesystem::remove_all(dir);
}

namespace {

/// A small real mesh for the tool commands.
const std::string kToolMesh = (kTestData / "obj/spot/spot.obj").string();

}  // namespace

TEST_CASE("bvh and bench commands: JSON output, usage errors") {
    const std::string& mesh = kToolMesh;
    const auto bvh =
        run_captured(run_bvh_command, {"bvh", mesh, "--builder", "sweep", "--size", "32", "--json"});
    REQUIRE(bvh.first == 0);
    for (const char* key :
         {"\"primitives\"", "\"nodes\"", "\"leaves\"", "\"max_depth\"", "\"sah_cost\"", "\"build_ms\"",
          "\"bytes\"", "\"leaf_size_histogram\"", "\"nodes_visited\"", "\"prims_tested\""})
        CHECK(bvh.second.find(key) != std::string::npos);
    const auto text = run_captured(run_bvh_command, {"bvh", mesh, "--size", "16"});
    CHECK(text.first == 0);
    CHECK(text.second.find("SAH cost") != std::string::npos);
    CHECK(run_captured(run_bvh_command, {"bvh", mesh, "--builder", "fast"}).first == 2);
    const auto reinsert = run_captured(
        run_bvh_command, {"bvh", mesh, "--builder", "reinsert", "--threads", "1", "--size", "16", "--json"});
    REQUIRE(reinsert.first == 0);
    for (const char* key :
         {"\"builder\":\"reinsert\"", "\"build_threads\":1", "\"mprims_s\"", "\"mprims_cpu_s\""})
        CHECK(reinsert.second.find(key) != std::string::npos);
    CHECK(run_captured(run_bvh_command, {"bvh", mesh, "--threads", "0"}).first == 2);
    CHECK(run_captured(run_bvh_command, {"bvh"}).first == 2);
    CHECK(run_captured(run_bvh_command, {"bvh", "/nonexistent.obj"}).first == 2);
    CHECK(run_captured(run_bvh_command, {"bvh", "--help"}).first == 0);

    const auto bench = run_captured(
        run_bench_command, {"bench", mesh, "--size", "32", "--repeat", "1", "--threads", "2", "--json"});
    REQUIRE(bench.first == 0);
    for (const char* key : {"\"mesh\"", "\"primitives\"", "\"threads\":2", "\"build_ms\"", "\"primary\"",
                            "\"diffuse\"", "\"shadow\"", "\"mrays_s\"", "\"hit_rate\""})
        CHECK(bench.second.find(key) != std::string::npos);
    if (!EmbreeReference::available())
        CHECK(bench.second.find("\"embree\":\"skipped: sahara was built without Embree 3\"") !=
              std::string::npos);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--embree-isa", "avx512skx"}).first == 2);
    const auto only = run_captured(run_bench_command, {"bench", mesh, "--size", "16", "--repeat", "1",
                                                       "--ray-set", "shadow", "--no-embree"});
    CHECK(only.first == 0);
    CHECK(only.second.find("primary") == std::string::npos);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--ray-set", "sideways"}).first == 2);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--threads", "0"}).first == 2);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--frobnicate"}).first == 2);
    CHECK(run_captured(run_bench_command, {"bench", "--help"}).first == 0);
}

TEST_CASE("bench command compares with Embree: default, robust and ISA-capped modes [needs Embree]" *
          doctest::skip(!EmbreeReference::available())) {
    const std::string& mesh = kToolMesh;
    const auto bench = run_captured(
        run_bench_command, {"bench", mesh, "--size", "32", "--repeat", "1", "--threads", "2", "--json"});
    REQUIRE(bench.first == 0);
    CHECK(bench.second.find("\"embree_mrays_s\"") != std::string::npos);
    CHECK(bench.second.find("\"embree_build_ms\"") != std::string::npos);
    CHECK(bench.second.find("\"embree_mtris_s\"") != std::string::npos);
    // Build speed per thread and against Embree, per elapsed and per CPU second.
    for (const char* key : {"\"mprims_s_per_thread\"", "\"embree_build_cpu_ms\"",
                            "\"embree_mtris_s_per_thread\"", "\"build_ratio\"", "\"build_ratio_cpu\""})
        CHECK_MESSAGE(bench.second.find(key) != std::string::npos, key);
    CHECK(bench.second.find("\"disagreements\":0") != std::string::npos);
    CHECK(bench.second.find("\"embree_mode\":\"default\"") != std::string::npos);
    // Embree's robust mode (robust traversal, accurate triangle test) answers the same rays alike.
    const auto robust =
        run_captured(run_bench_command, {"bench", mesh, "--size", "32", "--repeat", "1", "--ray-set",
                                         "diffuse", "--embree-robust", "--json"});
    REQUIRE(robust.first == 0);
    CHECK(robust.second.find("\"embree_mode\":\"robust\"") != std::string::npos);
    CHECK(robust.second.find("\"embree_mrays_s\"") != std::string::npos);
    CHECK(robust.second.find("\"disagreements\":0") != std::string::npos);
    const auto capped =
        run_captured(run_bench_command, {"bench", mesh, "--size", "16", "--repeat", "1", "--ray-set",
                                         "shadow", "--embree-isa", "sse2", "--json"});
    REQUIRE(capped.first == 0);
    CHECK(capped.second.find("\"embree_isa\":\"sse2\"") != std::string::npos);
    CHECK(capped.second.find("\"disagreements\":0") != std::string::npos);
}

TEST_CASE("bench --embree-quality: accepted names and bad values") {
    const std::string& mesh = kToolMesh;
    const TempDir tmp("embree_quality");
    const CliRun bad = run_sahara("bench " + mesh + " --embree-quality best", tmp);
    CHECK(bad.code == 2);
    CHECK(bad.err.find("--embree-quality: expected low|medium|high, got 'best'") != std::string::npos);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--embree-quality", "HIGH"}).first == 2);
    CHECK(run_captured(run_bench_command, {"bench", mesh, "--embree-quality"}).first == 2);
    // Without Embree the option is still accepted (and reported), the comparison skipped.
    const auto noembree = run_captured(
        run_bench_command,
        {"bench", mesh, "--size", "8", "--repeat", "1", "--embree-quality", "low", "--no-embree", "--json"});
    REQUIRE(noembree.first == 0);
    CHECK(noembree.second.find("\"embree_quality\":\"low\"") != std::string::npos);
}

TEST_CASE("bench against Embree at each build quality: same hits [needs Embree]" *
          doctest::skip(!EmbreeReference::available())) {
    for (const char* quality : {"low", "medium", "high"}) {
        CAPTURE(quality);
        const auto bench =
            run_captured(run_bench_command, {"bench", kToolMesh, "--size", "32", "--repeat", "1", "--threads",
                                             "2", "--embree-quality", quality, "--json"});
        REQUIRE(bench.first == 0);
        CHECK(bench.second.find(std::string("\"embree_quality\":\"") + quality + "\"") != std::string::npos);
        CHECK(bench.second.find("\"embree_mrays_s\"") != std::string::npos);
        // Every set (primary, packets, diffuse, shadow) agrees with sahara.
        size_t sets = 0;
        for (size_t at = bench.second.find("\"disagreements\":"); at != std::string::npos;
             at = bench.second.find("\"disagreements\":", at + 1)) {
            CHECK(bench.second.compare(at, 18, "\"disagreements\":0,") == 0);
            ++sets;
        }
        CHECK(sets == 4);
    }
}
