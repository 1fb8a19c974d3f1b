#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/cmd_converge.h"
#include "base/error.h"
#include "io/image_io.h"
#include "cli_test_util.h"
#include "io/plot.h"

using namespace sahara;

namespace {

/// Every <tag ...> element of `xml`, start tag to end tag (or "/>").
std::vector<std::string> elements(const std::string& xml, const std::string& tag) {
    std::vector<std::string> out;
    for (size_t at = xml.find("<" + tag + " "); at != std::string::npos;
         at = xml.find("<" + tag + " ", at + 1)) {
        const size_t gt = xml.find('>', at);
        const size_t end = xml[gt - 1] == '/' ? gt + 1 : xml.find("</" + tag + ">", at) + tag.size() + 3;
        out.push_back(xml.substr(at, end - at));
    }
    return out;
}

std::string attribute(const std::string& element, const std::string& name) {
    const size_t at = element.find(" " + name + "=\"");
    if (at == std::string::npos) return {};
    const size_t begin = at + name.size() + 3;
    return element.substr(begin, element.find('"', begin) - begin);
}

/// The text directly inside the element (for <polyline>: its <title>).
std::string content(const std::string& element) {
    size_t begin = element.find('>') + 1;
    if (element.compare(begin, 7, "<title>") == 0) begin += 7;
    return element.substr(begin, element.find('<', begin) - begin);
}

/// Checks that tags nest and close properly under a single <svg> root.
bool well_formed(const std::string& xml) {
    std::vector<std::string> open;
    int roots = 0;
    for (size_t at = xml.find('<'); at != std::string::npos; at = xml.find('<', at + 1)) {
        const size_t gt = xml.find('>', at);
        if (gt == std::string::npos) return false;
        const std::string tag = xml.substr(at + 1, gt - at - 1);
        if (tag[0] == '?') continue;
        if (tag[0] == '/') {
            if (open.empty() || open.back() != tag.substr(1)) return false;
            open.pop_back();
            continue;
        }
        const std::string name = tag.substr(0, tag.find_first_of(" /"));
        if (open.empty()) roots += name == "svg" ? 1 : 100;
        if (tag.back() != '/') open.push_back(name);
    }
    return open.empty() && roots == 1;
}

/// The value of a tick label element: "0.01", or "10" with a superscript exponent.
double tick_value(const std::string& element) {
    const size_t tspan = element.find("<tspan");
    if (tspan == std::string::npos) return std::stod(content(element));
    return std::pow(10.0, std::stod(content(element.substr(tspan))));
}

/// Pixel position -> log10(value) along one axis, fitted to the tick labels of `role`.
struct AxisMap {
    double a = 0, b = 0;  // log10(value) = a + b * pixel
    double value(double pixel) const { return std::pow(10.0, a + b * pixel); }
};

AxisMap axis_from_ticks(const std::string& svg, const std::string& role, const char* coordinate) {
    std::vector<std::pair<double, double>> ticks;  // pixel, log10(value)
    for (const std::string& t : elements(svg, "text"))
        if (attribute(t, "class") == role)
            ticks.emplace_back(std::stod(attribute(t, coordinate)), std::log10(tick_value(t)));
    REQUIRE(ticks.size() >= 2);
    AxisMap m;
    m.b = (ticks.back().second - ticks.front().second) / (ticks.back().first - ticks.front().first);
    m.a = ticks.front().second - m.b * ticks.front().first;
    for (const auto& [pixel, log_value] : ticks)
        CHECK(m.a + m.b * pixel == doctest::Approx(log_value).epsilon(1e-3));
    return m;
}

std::vector<std::pair<double, double>> polyline_points(const std::string& element) {
    std::vector<std::pair<double, double>> points;
    std::istringstream in(attribute(element, "points"));
    for (std::string xy; in >> xy;) {
        const size_t comma = xy.find(',');
        points.emplace_back(std::stod(xy.substr(0, comma)), std::stod(xy.substr(comma + 1)));
    }
    return points;
}

LogLogPlot two_series_plot() {
    LogLogPlot p;
    p.title = "test plot";
    p.x_label = "time (s)";
    p.y_label = "RMSE";
    p.series.push_back({"a <&> b", {0.1, 1, 10}, {1, 0.3, 0.1}, {1, 0, 0}, false});
    p.series.push_back({"second", {0.2, 2, 20}, {0.5, 0.2, 0.05}, {0, 0, 1}, false});
    p.series.push_back({"guide", {0.1, 20}, {1, 0.07}, {0.5f, 0.5f, 0.5f}, true});
    return p;
}

int count_pixels(const Image& img, bool (*match)(const float*)) {
    int n = 0;
    for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i) n += match(&img.rgba[4 * i]);
    return n;
}

bool dark(const float* p) { return p[0] < 0.3f && p[1] < 0.3f && p[2] < 0.3f; }
bool red(const float* p) { return p[0] > 0.7f && p[1] < 0.3f && p[2] < 0.3f; }

}  // namespace

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

TEST_CASE("plot: decade tick labels") {
    CHECK(decade_label(-2).text == "0.01");
    CHECK(decade_label(0).text == "1");
    CHECK(decade_label(3).text == "1000");
    CHECK(decade_label(3).superscript.empty());
    CHECK(decade_label(-5).text == "10");
    CHECK(decade_label(-5).superscript == "-5");
    CHECK(decade_label(12).superscript == "12");
}

TEST_CASE("plot: exponents are superscripts in the SVG") {
    LogLogPlot p;
    p.series.push_back({"tiny", {1e-6, 1e-5}, {1e-8, 1e-7}, {0, 0, 0}, false});
    const std::string svg = plot_svg(layout_loglog_plot(p));
    CHECK(well_formed(svg));
    CHECK(svg.find(">10<tspan") != std::string::npos);
    std::vector<double> y_ticks;
    for (const std::string& t : elements(svg, "text"))
        if (attribute(t, "class") == "tick-y") y_ticks.push_back(tick_value(t));
    REQUIRE(y_ticks.size() == 2);
    CHECK(y_ticks[0] == doctest::Approx(1e-8));
    CHECK(y_ticks[1] == doctest::Approx(1e-7));
}

TEST_CASE("plot: the SVG is well-formed and shows axes, ticks, legend and every series at its values") {
    const LogLogPlot plot = two_series_plot();
    const std::string svg = plot_svg(layout_loglog_plot(plot, 640, 480));
    CHECK(svg.rfind("<?xml", 0) == 0);
    CHECK(well_formed(svg));
    CHECK(attribute(elements(svg, "svg").at(0), "width") == "640");
    CHECK(svg.find("a &lt;&amp;&gt; b") != std::string::npos);  // labels are escaped
    std::vector<std::string> texts;
    for (const std::string& t : elements(svg, "text")) texts.push_back(content(t));
    for (const char* expected :
         {"test plot", "time (s)", "RMSE", "0.01", "0.1", "1", "10", "100", "second", "guide"})
        CHECK_MESSAGE(std::find(texts.begin(), texts.end(), expected) != texts.end(), expected);
    int minor_ticks = 0;
    for (const std::string& p : elements(svg, "polyline")) minor_ticks += attribute(p, "class") == "tick";
    CHECK(minor_ticks > 20);  // 2..9 between decades on both axes

    const AxisMap x = axis_from_ticks(svg, "tick-x", "x"), y = axis_from_ticks(svg, "tick-y", "y");
    int series = 0;
    for (const std::string& p : elements(svg, "polyline")) {
        if (attribute(p, "class") != "series") continue;
        const PlotSeries& s = plot.series[size_t(series++)];
        const auto points = polyline_points(p);
        REQUIRE(points.size() == s.x.size());
        for (size_t i = 0; i < points.size(); ++i) {
            CHECK(x.value(points[i].first) == doctest::Approx(s.x[i]).epsilon(0.005));
            CHECK(y.value(points[i].second) == doctest::Approx(s.y[i]).epsilon(0.005));
        }
    }
    CHECK(series == 2);
    int guides = 0;
    for (const std::string& p : elements(svg, "polyline")) guides += attribute(p, "class") == "guide";
    CHECK(guides == 1);
}

TEST_CASE("plot: the PNG is drawn by the codec, with text when a font is found and without otherwise") {
    const std::string file = (std::filesystem::temp_directory_path() / "sahara_test_plot.png").string();
    PlotDrawing d;
    d.width = 240;
    d.height = 60;
    d.fonts = layout_loglog_plot({}).fonts;
    d.items.emplace_back(PlotText{"title",
                                  "Hello 10⁻²",
                                  {10, 40},
                                  28,
                                  {0, 0, 0},
                                  TextAnchor::start,
                                  TextBaseline::alphabetic,
                                  false,
                                  {}});
    d.items.emplace_back(PlotPath{"series", {{160, 10}, {230, 50}}, {1, 0, 0}, 3, 0, {}});
    const std::string warning = write_plot_png(file, d);
    const auto with_font = read_image(file, false);
    CHECK(with_font->width == 240);
    CHECK(count_pixels(*with_font, red) > 50);
    if (std::filesystem::exists("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")) CHECK(warning.empty());
    if (warning.empty())
        CHECK(count_pixels(*with_font, dark) > 100);
    else
        MESSAGE("no font: " << warning);

    // Empty title and axis labels: nothing to draw, no undefined text box measured.
    CHECK(write_plot_png(file, layout_loglog_plot({}, 300, 200)) == warning);

    d.fonts = {"no-such-font-anywhere"};
    CHECK(write_plot_png(file, d).find("no TrueType font") != std::string::npos);
    const auto without_font = read_image(file, false);
    CHECK(count_pixels(*without_font, dark) == 0);
    CHECK(count_pixels(*without_font, red) > 50);
    std::filesystem::remove(file);
}

TEST_CASE("converge: end to end on a tiny default scene writes CSV, plots and reference that agree") {
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
    std::map<std::string, std::vector<std::pair<double, double>>> rows;  // config -> (seconds, rmse)
    for (std::string line; std::getline(csv, line);) {
        if (line.empty()) continue;
        std::istringstream fields(line);
        std::string config, spp, seconds, rmse;
        std::getline(fields, config, ',');
        std::getline(fields, spp, ',');
        std::getline(fields, seconds, ',');
        std::getline(fields, rmse, ',');
        rows[config].emplace_back(std::stod(seconds), std::stod(rmse));
    }
    REQUIRE(rows.size() == 2);

    const std::string svg = sahara::test::read_text(prefix + ".svg");
    CHECK(well_formed(svg));
    const AxisMap x = axis_from_ticks(svg, "tick-x", "x"), y = axis_from_ticks(svg, "tick-y", "y");
    int series = 0;
    for (const std::string& p : elements(svg, "polyline")) {
        if (attribute(p, "class") != "series") continue;
        ++series;
        const std::string label = content(p);
        const std::string config = label.substr(0, label.find(" (slope"));
        REQUIRE(rows.count(config) == 1);
        const auto points = polyline_points(p);
        REQUIRE(points.size() == rows[config].size());
        for (size_t i = 0; i < points.size(); ++i) {
            CHECK(x.value(points[i].first) == doctest::Approx(rows[config][i].first).epsilon(0.01));
            CHECK(y.value(points[i].second) == doctest::Approx(rows[config][i].second).epsilon(0.01));
        }
    }
    CHECK(series == 2);
    int legend_entries = 0;
    for (const std::string& t : elements(svg, "text"))
        legend_entries += attribute(t, "class") == "legend" && (content(t).rfind("sobol (slope", 0) == 0 ||
                                                                content(t).rfind("random (slope", 0) == 0);
    CHECK(legend_entries == 2);

    const auto plot = read_image(prefix + ".png", false);
    CHECK(plot->width == 900);
    const auto ref = read_image(prefix + "-reference.exr", false);
    CHECK(ref->width == 32);
    for (const char* ext : {".csv", ".svg", ".png", "-reference.exr"}) std::filesystem::remove(prefix + ext);
    CHECK(run_converge_command({"--bogus"}) == 2);
}
