// `sahara bench --generated-mesh N` end to end, through the real executable: the
// in-memory sphere is built, traced and reported with the memory figures.
#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include "cli_test_util.h"

using namespace sahara::test;

TEST_CASE("bench --generated-mesh builds and traces exactly N triangles and reports memory") {
    TempDir dir("bench_generated");
    const CliRun run =
        run_sahara("bench --generated-mesh 2000 --no-embree --json --size 16 --repeat 1 --threads 2", dir);
    REQUIRE(run.code == 0);
    const auto j = nlohmann::json::parse(run.out);
    CHECK(j["primitives"] == 2000);
    CHECK(j["input"] == "mesh");
    CHECK(j["mesh"].get<std::string>().find("generated") != std::string::npos);
    CHECK(j["embree"] == "skipped: --no-embree");
    // The camera frames the sphere's box: some primary rays hit it, not all.
    CHECK(j["rays"]["primary"]["hit_rate"].get<double>() > 0.05);
    CHECK(j["rays"]["primary"]["hit_rate"].get<double>() < 0.95);
    CHECK(j["tree_bytes_per_primitive"].get<double>() > 0.0);
    const auto& m = j["memory"];
    CHECK(m["input_rss_mib"].get<double>() > 0.0);
    CHECK(m["sahara_build_rss_mib"].get<double>() > 0.0);
    // The peak while the build ran is at least what it left.
    CHECK(m["sahara_build_peak_rss_mib"].get<double>() >= m["sahara_build_rss_mib"].get<double>() - 1.0);
    CHECK_FALSE(m.contains("embree_build_rss_mib"));

    const CliRun text = run_sahara("bench --generated-mesh 600 --no-embree --size 8 --repeat 1", dir);
    REQUIRE(text.code == 0);
    CHECK(text.out.find("primitives  600 (600 triangles)") != std::string::npos);
    CHECK(text.out.find("memory      resident MiB after (peak during)") != std::string::npos);
}

TEST_CASE("bench --generated-mesh refuses odd counts and a file besides it with exit 2") {
    TempDir dir("bench_generated_bad");
    const CliRun odd = run_sahara("bench --generated-mesh 1001 --no-embree", dir);
    CHECK(odd.code == 2);
    CHECK(odd.err.find("--generated-mesh: a closed sphere grid has an even number") != std::string::npos);
    const CliRun both = run_sahara("bench some.obj --generated-mesh 1000 --no-embree", dir);
    CHECK(both.code == 2);
    CHECK(both.err.find("or --generated-mesh N") != std::string::npos);
}

TEST_CASE("bench gives no ratio for a ray set with no rays instead of printing nan") {
    // The camera looks away from the only triangle: no primary ray hits, so the diffuse
    // and shadow sets (spawned from hits) are empty and have no rate to compare.
    TempDir dir("bench_empty_sets");
    {
        std::ofstream(dir / "tri.obj") << "v 0 100 0\nv 1 100 0\nv 0 100 1\nf 1 2 3\n";
        std::ofstream(dir / "away.json") << R"({"camera": {"position": [0, 0, 0], "look_at": [0, -1, 0]},
                   "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [1, 1, 1]}],
                   "materials": {"grey": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]}},
                   "objects": [{"type": "mesh", "file": "tri.obj", "material": "grey"}]})";
    }
    const CliRun run = run_sahara("bench away.json --json --size 16 --repeat 1 --threads 1", dir);
    REQUIRE(run.code == 0);
    const auto j = nlohmann::json::parse(run.out);
    CHECK(j["rays"]["primary"]["hit_rate"] == 0.0);
    CHECK(j["rays"]["shadow"]["count"] == 0);
    if (j.contains("embree_build_ms")) {
        CHECK(j["rays"]["shadow"]["ratio"].is_null());
        CHECK(j["rays"]["shadow"]["ratio_cpu"].is_null());
        CHECK(j["rays"]["primary"]["ratio"].is_number());
    }
    const CliRun text = run_sahara("bench away.json --size 16 --repeat 1 --threads 1", dir);
    REQUIRE(text.code == 0);
    CHECK(text.out.find("nan") == std::string::npos);
    CHECK(text.out.find("shadow") != std::string::npos);
}
