#include "app/cmd_converge.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include <omp.h>

#include "pipeline/mesh_input.h"
#include "base/error.h"
#include "base/log.h"
#include "io/image_io.h"
#include "io/plot.h"
#include "render/film.h"
#include "render/progress.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "io/scene_parser.h"

namespace sahara {

const char* const kConvergeUsage =
    "usage: sahara converge [SCENE.json] [--reference REF.exr] [--budget SECONDS] [-o PREFIX]\n"
    "                       [--compare \"LABEL=FLAGS\"]... [render flags]\n"
    "\n"
    "Renders SCENE (or the built-in default scene) at 1, 2, 4, ... samples per pixel\n"
    "until the next doubling would exceed the time budget, and measures the error of\n"
    "each image against a reference: RMSE = sqrt(mean (x - ref)^2) and\n"
    "relMSE = mean (x - ref)^2 / (ref^2 + 0.01), over pixels and RGB channels, on\n"
    "linear radiance; efficiency = 1 / (relMSE * seconds). Without --reference, a\n"
    "reference is rendered at 16x the largest spp (with another seed; capped at 8x\n"
    "the budget) and written to PREFIX-reference.exr for reuse.\n"
    "Writes PREFIX.csv (one row per measured image) and a log-log plot of RMSE against\n"
    "render time, one line per configuration with the ideal Monte Carlo slope -1/2 as a\n"
    "guide: PREFIX.svg (opens in any web browser) and PREFIX.png (needs a TrueType font\n"
    "for its text, e.g. Debian's fonts-dejavu-core).\n"
    "\n"
    "  --reference FILE     reference image (.exr/.hdr/.pfm, same size as the render)\n"
    "  --budget S           render seconds per configuration (default 10)\n"
    "  --max-spp N          stop the series at N samples per pixel (default 65536)\n"
    "  -o, --output PREFIX  output prefix (default 'converge')\n"
    "  --compare \"L=FLAGS\"  measure a configuration labelled L with extra render flags,\n"
    "                       e.g. --compare \"sobol=--sampler sobol\" --compare \"random=--sampler "
    "independent\"\n"
    "  --threads N          worker threads (default: all)\n"
    "  --width W, --height H, --max-depth D, --seed S, --sampler NAME, ...: as for render\n"
    "  -h, --help           this text\n";

namespace {

using Clock = std::chrono::steady_clock;

ConvergeConfig parse_config(const std::string& spec) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0)
        throw UsageError("--compare: expected \"LABEL=FLAGS\", got '" + spec + "'");
    ConvergeConfig c;
    c.label = spec.substr(0, eq);
    std::istringstream in(spec.substr(eq + 1));
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    CLI::App app;
    bool help = false;
    configure_app(app, help);
    add_render_flags(app, c.overrides);
    try {
        const std::vector<std::string> rest = parse_command_line(app, words);
        if (help || !rest.empty())
            throw UsageError("unknown option '" + (help ? std::string("--help") : rest[0]) + "'");
    } catch (const UsageError& e) {
        const std::string what = e.what();
        const std::string unknown = "unknown option '";
        if (what.rfind(unknown, 0) == 0)
            throw UsageError("--compare '" + c.label + "': unknown render flag '" +
                             what.substr(unknown.size()));
        throw UsageError("--compare '" + c.label + "': " + what);
    }
    return c;
}

/// One measured point of a configuration's series.
struct Point {
    int spp;
    double seconds;
    std::vector<float> rgb;
    ImageError error;
};

struct Series {
    std::string label;
    std::vector<Point> points;
    double slope = 0;
};

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// A configuration being measured.
struct Run {
    std::unique_ptr<Scene>
        scene;  ///< on the heap: a Scene must not move after build (its accelerator points to it)
    std::unique_ptr<Film> film;
    Series series;
    double elapsed = 0;
    int done = 0;
    bool finished = false;
};

/// Renders the doubling series of every configuration within the budget. The
/// configurations take turns, one doubling each, so that a change in machine
/// load over the run affects them alike (equal-time comparisons stay fair).
std::vector<Series> measure_all(const std::vector<SceneDesc>& descs,
                                const std::vector<ConvergeConfig>& configs, const ConvergeArgs& a,
                                int threads) {
    std::vector<Run> runs;
    for (size_t i = 0; i < descs.size(); ++i) {
        Run r{std::unique_ptr<Scene>(new Scene(build_scene(descs[i]))),
              std::make_unique<Film>(descs[i].render.width, descs[i].render.height),
              {}};
        r.series.label = configs[i].label;
        runs.push_back(std::move(r));
    }
    const bool tty = Progress::stderr_is_tty();
    for (bool any = true; any;) {
        any = false;
        for (Run& r : runs) {
            if (r.finished) continue;
            any = true;
            const int next = std::max(1, r.done * 2);
            const auto t0 = Clock::now();
            render_pass(*r.scene, *r.film, r.done, next, threads, nullptr);
            r.elapsed += seconds_since(t0);
            r.done = next;
            r.series.points.push_back({r.done, r.elapsed, r.film->to_rgb(), {}});
            // The next doubling costs about as much as everything so far.
            r.finished = 2 * r.elapsed > a.budget_s || r.done * 2 > a.max_spp;
            if (tty)
                std::fprintf(stderr, "\r  %-12s %7d spp  %8.2f s   ", r.series.label.c_str(), r.done,
                             r.elapsed);
        }
    }
    if (tty) std::fprintf(stderr, "\n");
    std::vector<Series> all;
    for (Run& r : runs) {
        if (r.film->nonfinite_samples() > 0)
            log_warning(r.series.label + ": " + std::to_string(r.film->nonfinite_samples()) +
                        " non-finite samples were discarded");
        all.push_back(std::move(r.series));
    }
    return all;
}

/// Renders a reference at 16x the largest measured spp, with another seed so its
/// noise is independent of the measured images; capped at 8x the budget.
std::vector<float> render_reference(SceneDesc desc, const ConvergeArgs& a, const std::vector<Series>& all,
                                    int threads) {
    const Series& basis = all[0];
    const Point& last = basis.points.back();
    const double per_spp = last.seconds / last.spp;
    int largest = 0;
    for (const Series& s : all) largest = std::max(largest, s.points.back().spp);
    int spp = 16 * largest;
    const int cap = std::max(largest * 2, int(8 * a.budget_s / per_spp));
    if (spp > cap) spp = cap;
    desc.render.seed = desc.render.seed * 0x9e3779b97f4a7c15ull + 0x7261726566ull;
    std::fprintf(stderr,
                 "sahara converge: no --reference given: rendering one at %d spp (%s settings, another seed, "
                 "about %.0f s)\n",
                 spp, basis.label.c_str(), per_spp * spp);
    if (spp < 16 * largest)
        log_warning("reference capped at " + std::to_string(spp) + " spp (< 16x the largest measured " +
                    std::to_string(largest) + "): its own noise inflates the smallest errors");
    const Scene scene = build_scene(desc);
    Film film(desc.render.width, desc.render.height);
    for (int done = 0; done < spp;) {
        const int end = std::min(spp, done + 256);
        render_pass(scene, film, done, end, threads, nullptr);
        done = end;
    }
    const std::string file = a.prefix + "-reference.exr";
    std::vector<float> rgb = film.to_rgb();
    write_image(
        file, film.width(), film.height(), rgb,
        {{"scene", desc.source}, {"spp", std::to_string(spp)}, {"seed", std::to_string(desc.render.seed)}});
    std::fprintf(stderr, "sahara converge: reference written to %s\n", file.c_str());
    return rgb;
}

std::vector<float> load_reference(const std::string& file, int width, int height) {
    const auto img = read_image(file, false);
    if (img->width != width || img->height != height)
        throw input_error(file, "",
                          "reference is " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                              " but the render is " + std::to_string(width) + "x" + std::to_string(height));
    std::vector<float> rgb(size_t(width) * size_t(height) * 3);
    for (size_t i = 0; i < size_t(width) * size_t(height); ++i)
        for (size_t c = 0; c < 3; ++c) rgb[3 * i + c] = img->rgba[4 * i + c];
    return rgb;
}

/// A CSV field: quoted (with doubled quotes) when it holds a comma or a quote.
std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) {
        if (c == '"') q.push_back('"');
        q.push_back(c);
    }
    q.push_back('"');
    return q;
}

void write_csv(const std::string& file, const std::vector<Series>& all) {
    std::ofstream out(file);
    if (!out) throw input_error(file, "", "cannot write");
    out << "config,spp,seconds,rmse,relmse,efficiency\n";
    char line[256];
    for (const Series& s : all)
        for (const Point& p : s.points) {
            std::snprintf(line, sizeof line, ",%d,%.6g,%.6g,%.6g,%.6g\n", p.spp, p.seconds, p.error.rmse,
                          p.error.relmse, 1.0 / (p.error.relmse * p.seconds));
            out << csv_field(s.label) << line;
        }
    if (!out) throw input_error(file, "", "write failed");
}

/// The series as a log-log plot of RMSE against seconds, with the Monte Carlo
/// rate as a guide.
LogLogPlot convergence_plot(const std::vector<Series>& all, const std::string& scene_name) {
    // Distinct hues that stay apart for the common forms of colour blindness.
    static const PlotColor kColors[] = {{0.00f, 0.45f, 0.70f}, {0.84f, 0.37f, 0.00f}, {0.00f, 0.62f, 0.45f},
                                        {0.80f, 0.47f, 0.65f}, {0.34f, 0.71f, 0.91f}, {0.90f, 0.62f, 0.00f}};
    LogLogPlot plot;
    plot.title = "RMSE against render time: " + scene_name;
    plot.x_label = "render time (s)";
    plot.y_label = "RMSE against the reference";
    for (size_t i = 0; i < all.size(); ++i) {
        PlotSeries ps;
        char label[160];
        std::snprintf(label, sizeof label, "%s (slope %.2f)", all[i].label.c_str(), all[i].slope);
        ps.label = label;
        ps.color = kColors[i % std::size(kColors)];
        for (const Point& p : all[i].points) {
            ps.x.push_back(p.seconds);
            ps.y.push_back(p.error.rmse);
        }
        plot.series.push_back(ps);
    }
    // The Monte Carlo rate, error ~ time^-1/2, through the first series' first point.
    double t_max = 0;
    for (const Series& s : all) t_max = std::max(t_max, s.points.back().seconds);
    const Point& p0 = all[0].points.front();
    PlotSeries ideal;
    ideal.label = "ideal Monte Carlo rate (slope -0.50)";
    ideal.color = {0.45f, 0.45f, 0.45f};
    ideal.dashed = true;
    ideal.x = {p0.seconds, t_max};
    ideal.y = {p0.error.rmse, p0.error.rmse * std::sqrt(p0.seconds / t_max)};
    plot.series.push_back(ideal);
    return plot;
}

/// Writes PREFIX.svg and PREFIX.png from one layout; returns the files written.
/// A PNG that cannot be drawn is reported, not fatal: the SVG holds the same plot.
std::vector<std::string> write_plots(const std::string& prefix, const LogLogPlot& plot) {
    const PlotDrawing drawing = layout_loglog_plot(plot);
    std::vector<std::string> written;
    write_plot_svg(prefix + ".svg", drawing);
    written.push_back(prefix + ".svg");
    try {
        if (const std::string warning = write_plot_png(prefix + ".png", drawing); !warning.empty())
            log_warning(prefix + ".png: " + warning);
        written.push_back(prefix + ".png");
    } catch (const InputError& e) {
        log_warning(std::string("no PNG plot: ") + e.what());
    }
    return written;
}

void print_summary(const std::vector<Series>& all) {
    std::printf("%-14s %8s %10s %12s %12s %12s\n", "config", "spp", "seconds", "RMSE", "relMSE",
                "efficiency");
    for (const Series& s : all)
        for (const Point& p : s.points)
            std::printf("%-14s %8d %10.3f %12.5g %12.5g %12.5g\n", s.label.c_str(), p.spp, p.seconds,
                        p.error.rmse, p.error.relmse, 1.0 / (p.error.relmse * p.seconds));
    double t = INFINITY;
    for (const Series& s : all) t = std::min(t, s.points.back().seconds);
    std::printf("\nfitted slope of log RMSE against log seconds (ideal Monte Carlo: -0.50):\n");
    for (const Series& s : all) {
        if (s.points.size() < 2)
            std::printf("  %-14s n/a (one point: raise --budget)\n", s.label.c_str());
        else
            std::printf("  %-14s %6.3f\n", s.label.c_str(), s.slope);
    }
    std::printf("equal-time comparison at %.3f s (log-log interpolation):\n", t);
    double base = 0;
    for (const Series& s : all) {
        std::vector<double> x, y;
        for (const Point& p : s.points) {
            x.push_back(p.seconds);
            y.push_back(p.error.relmse);
        }
        const double relmse = loglog_interpolate(x, y, t);
        if (base == 0) base = relmse;
        std::printf("  %-14s relMSE %.5g  (x%.3f of %s)\n", s.label.c_str(), relmse, relmse / base,
                    all[0].label.c_str());
    }
}

int run(const ConvergeArgs& a) {
    SceneDesc base = read_scene_argument(a.scene);
    a.overrides.apply(base.render);
    const int threads = a.threads > 0 ? a.threads : omp_get_max_threads();
    std::vector<ConvergeConfig> configs = a.configs;
    if (configs.empty()) configs.push_back({"render", {}});
    std::vector<SceneDesc> descs;
    for (const ConvergeConfig& c : configs) {
        SceneDesc d = base;
        c.overrides.apply(d.render);
        descs.push_back(std::move(d));
    }
    std::vector<Series> all = measure_all(descs, configs, a, threads);
    const std::vector<float> reference =
        a.reference ? load_reference(*a.reference, base.render.width, base.render.height)
                    : render_reference(descs[0], a, all, threads);
    for (Series& s : all) {
        std::vector<double> x, y;
        for (Point& p : s.points) {
            p.error = image_error(p.rgb, reference);
            x.push_back(p.seconds);
            y.push_back(p.error.rmse);
        }
        s.slope = fit_loglog_slope(x, y);
    }
    write_csv(a.prefix + ".csv", all);
    const std::vector<std::string> plots =
        write_plots(a.prefix, convergence_plot(all, a.scene ? *a.scene : std::string("default scene")));
    print_summary(all);
    std::printf("wrote %s.csv (the measurements)", a.prefix.c_str());
    for (const std::string& file : plots) std::printf(", %s", file.c_str());
    std::printf(" (log-log plot of RMSE against render time)\n");
    return 0;
}

}  // namespace

ConvergeArgs parse_converge_args(const std::vector<std::string>& args) {
    ConvergeArgs r;
    CLI::App app;
    configure_app(app, r.help);
    app.add_option("-o,--output", r.prefix);
    app.add_option_function<std::string>("--reference", [&r](const std::string& v) { r.reference = v; });
    app.add_option_function<std::string>(
        "--budget", [&r](const std::string& v) { r.budget_s = parse_real_value("--budget", v, 0.001, 1e6); });
    app.add_option_function<std::string>("--max-spp", [&r](const std::string& v) {
        r.max_spp = int(parse_int_value("--max-spp", v, 1, 1 << 24));
    });
    add_threads_option(app, r.threads);
    std::vector<std::string> compare;
    app.add_option("--compare", compare)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    add_render_flags(app, r.overrides);
    const std::vector<std::string> scenes = parse_command_line(app, args);
    if (scenes.size() > 1)
        throw UsageError("more than one scene given ('" + scenes[0] + "' and '" + scenes[1] + "')");
    if (!scenes.empty()) r.scene = scenes[0];
    for (const std::string& spec : compare) r.configs.push_back(parse_config(spec));
    return r;
}

ImageError image_error(const std::vector<float>& rgb, const std::vector<float>& reference) {
    ImageError e;
    const size_t n = std::min(rgb.size(), reference.size());
    if (n == 0) return e;
    double se = 0, rel = 0;
    for (size_t i = 0; i < n; ++i) {
        const double d = double(rgb[i]) - double(reference[i]);
        se += d * d;
        rel += d * d / (double(reference[i]) * double(reference[i]) + 1e-2);
    }
    e.rmse = std::sqrt(se / double(n));
    e.relmse = rel / double(n);
    return e;
}

double fit_loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
        if (!(x[i] > 0) || !(y[i] > 0)) continue;
        const double lx = std::log(x[i]), ly = std::log(y[i]);
        sx += lx;
        sy += ly;
        sxx += lx * lx;
        sxy += lx * ly;
        ++n;
    }
    const double den = n * sxx - sx * sx;
    return n >= 2 && den > 0 ? (n * sxy - sx * sy) / den : 0.0;
}

double loglog_interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
    if (x.empty()) return 0;
    if (at <= x.front()) return y.front();
    for (size_t i = 1; i < x.size(); ++i)
        if (at <= x[i]) {
            const double t = std::log(at / x[i - 1]) / std::log(x[i] / x[i - 1]);
            return y[i - 1] * std::pow(y[i] / y[i - 1], t);
        }
    return y.back();
}

int run_converge_command(const std::vector<std::string>& args) {
    ConvergeArgs a;
    try {
        a = parse_converge_args(args);
    } catch (const UsageError& e) {
        return usage_error("converge", e.what());
    }
    if (a.help) {
        std::fputs(kConvergeUsage, stdout);
        return 0;
    }
    try {
        check_output_path(a.prefix + ".png");
        return run(a);
    } catch (const InputError& e) {
        std::fprintf(stderr, "sahara: error: %s\n", e.what());
        return 2;
    }
}

}  // namespace sahara
