#pragma once
/// `sahara converge`: error against render time over a doubling series of
/// samples per pixel, for one or several configurations, as CSV and a plot.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/render_args.h"

namespace sahara {

/// `sahara converge`: arguments after the command name; returns the exit code.
int run_converge_command(const std::vector<std::string>& args);

/// One configuration to measure: a label and its render flags.
struct ConvergeConfig {
    std::string label;
    RenderOverrides overrides;
};

struct ConvergeArgs {
    std::optional<std::string> scene;      ///< none: the built-in default scene
    std::optional<std::string> reference;  ///< none: render one
    double budget_s = 10.0;                ///< render time per configuration
    int max_spp = 1 << 16;
    std::string prefix = "converge";
    int threads = 0;
    bool help = false;
    RenderOverrides overrides;            ///< applied to every configuration
    std::vector<ConvergeConfig> configs;  ///< from --compare; empty: one "render"
};

/// Parses the arguments after `converge`. Throws UsageError.
ConvergeArgs parse_converge_args(const std::vector<std::string>& args);

/// Error of an RGB image (3 floats per pixel) against a reference of the same size.
struct ImageError {
    double rmse = 0;    ///< sqrt(mean over pixels and channels of (x - ref)^2)
    double relmse = 0;  ///< mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01)
};
ImageError image_error(const std::vector<float>& rgb, const std::vector<float>& reference);

/// Least-squares slope of log(y) against log(x) (points with x, y > 0).
double fit_loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

/// y at `x` by log-log linear interpolation of the polyline (x sorted
/// ascending); clamped to the end points outside the range.
double loglog_interpolate(const std::vector<double>& x, const std::vector<double>& y, double at);

extern const char* const kConvergeUsage;

}  // namespace sahara
