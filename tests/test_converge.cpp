#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/cmd_converge.h"
#include "io/image_io.h"
#include "io/plot.h"

using namespace sahara;

TEST_CASE("converge: arguments") {
    const ConvergeArgs a = parse_converge_args({"scene.json", "--budget", "2.5", "-o", "out/x", "--compare",
                                                "sobol=--sampler sobol --spp 4", "--compare",
                                                "random=--sampler independent", "--width", "32"});
    CHECK(*a.scene == "scene.json");
    CHECK(a.budget_s == 2.5);
    CHECK(a.prefix == "out/x");
    REQUIRE(a.configs.size() == 2);
    CHECK(a.configs[0].label == "sobol");
    CHECK(*a.configs[0].overrides.sampler == SamplerType::sobol);
    CHECK(*a.configs[1].overrides.sampler == SamplerType::independent);
    CHECK(*a.overrides.width == 32);
    CHECK_THROWS_AS(parse_converge_args({"--compare", "nolabel"}), UsageError);
    CHECK_THROWS_AS(parse_converge_args({"--compare", "x=--bogus"}), UsageError);
    CHECK_THROWS_AS(parse_converge_args({"--budget", "-1"}), UsageError);
}

TEST_CASE("converge: error metrics and slope fit") {
    const std::vector<float> ref = {1, 1, 1, 0, 0, 0};
    const std::vector<float> img = {1, 1, 3, 0, 0, 0.1f};
    const ImageError e = image_error(img, ref);
    CHECK(e.rmse == doctest::Approx(std::sqrt((4.0 + 0.01) / 6)));
    CHECK(e.relmse == doctest::Approx((4.0 / 1.01 + 0.01 / 0.01) / 6).epsilon(1e-6));
    // y = 3 x^-0.5 exactly: slope -0.5; interpolation follows the power law.
    std::vector<double> x = {1, 2, 4, 8}, y;
    for (double v : x) y.push_back(3 / std::sqrt(v));
    CHECK(fit_loglog_slope(x, y) == doctest::Approx(-0.5));
    CHECK(loglog_interpolate(x, y, 3.0) == doctest::Approx(3 / std::sqrt(3.0)));
    CHECK(loglog_interpolate(x, y, 100.0) == doctest::Approx(y.back()));
}

TEST_CASE("plot: axes, labels and series land in the image") {
    CHECK(decade_label(-2) == "0.01");
    CHECK(decade_label(3) == "1000");
    CHECK(decade_label(-5) == "1E-5");
    LogLogPlot p;
    p.title = "test plot";
    p.series.push_back({"a", {0.1, 1, 10}, {1, 0.3, 0.1}, {1, 0, 0}, false});
    const Raster r = draw_loglog_plot(p, 400, 300);
    int red = 0;
    for (size_t i = 0; i < r.rgb.size(); i += 3) red += r.rgb[i] == 1.0f && r.rgb[i + 1] == 0.0f;
    CHECK(red > 100);  // the series line and markers
}

TEST_CASE("converge: end to end on a tiny default scene writes CSV, plot and reference") {
    const std::string prefix = (std::filesystem::temp_directory_path() / "sahara_test_converge").string();
    // Tiny image and budget: a smoke test of the whole command, files included.
    const int rc = run_converge_command(
        {"--width", "32", "--height", "24", "--budget", "0.3", "--max-spp", "64", "--threads", "2", "-o",
         prefix, "--compare", "sobol=--sampler sobol", "--compare", "random=--sampler independent"});
    REQUIRE(rc == 0);
    std::ifstream csv(prefix + ".csv");
    std::string header;
    std::getline(csv, header);
    CHECK(header == "config,spp,seconds,rmse,relmse,efficiency");
    int rows = 0;
    for (std::string line; std::getline(csv, line);) rows += !line.empty();
    CHECK(rows >= 2);
    const auto plot = read_image(prefix + ".png", false);
    CHECK(plot->width == 900);
    const auto ref = read_image(prefix + "-reference.exr", false);
    CHECK(ref->width == 32);
    for (const char* ext : {".csv", ".png", "-reference.exr"}) std::filesystem::remove(prefix + ext);
    CHECK(run_converge_command({"--bogus"}) == 2);
}
