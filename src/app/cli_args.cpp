#include "app/cli_args.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "accel/bvh.h"
#include "app/render_args.h"
#include "render/tonemap.h"

namespace sahara {

int usage_error(const std::string& command, const std::string& message) {
    const std::string program = command.empty() ? "sahara" : "sahara " + command;
    std::fprintf(stderr, "%s: %s (see '%s --help')\n", program.c_str(), message.c_str(), program.c_str());
    return 2;
}

void configure_app(CLI::App& app, bool& help) {
    app.set_help_flag();  // each command prints its own text, with its examples
    app.add_flag("-h,--help", help);
    app.allow_extras();  // kept in remaining(), named by parse_command_line
    app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

namespace {

/// CLI11's message, reworded where it has a shorter one-line form.
std::string usage_message(const CLI::ParseError& e) {
    const std::string what = e.what();
    // ArgumentMismatch::TypedAtLeast: "--spp: 1 required TEXT missing"
    const size_t colon = what.find(": ");
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && colon != std::string::npos && what.size() >= 8 &&
        what.compare(what.size() - 8, 8, " missing") == 0)
        return what.substr(0, colon) + ": missing value";
    return what;
}

}  // namespace

std::vector<std::string> parse_command_line(CLI::App& app, const std::vector<std::string>& args) {
    std::vector<std::string> positional;
    app.add_option("args", positional);
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 consumes from the back
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw UsageError(usage_message(e));
    }
    for (const std::string& a : app.remaining())
        if (a.size() > 1 && a[0] == '-' && a != "--") throw UsageError("unknown option '" + a + "'");
    return positional;
}

long long parse_int_value(const std::string& flag, const std::string& value, long long lo, long long hi) {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        throw UsageError(flag + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                         ", got '" + value + "'");
    return v;
}

uint64_t parse_uint64_value(const std::string& flag, const std::string& value) {
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
    if (value.empty() || value[0] == '-' || *end != '\0' || errno == ERANGE)
        throw UsageError(flag + ": expected an integer in 0.." + std::to_string(UINT64_MAX) + ", got '" +
                         value + "'");
    return uint64_t(v);
}

double parse_real_value(const std::string& flag, const std::string& value, double lo, double hi) {
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
        throw UsageError(flag + ": expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got '" + value + "'");
    return v;
}

std::pair<int, int> parse_size_value(const std::string& flag, const std::string& value) {
    const size_t x = value.find('x');
    if (x == std::string::npos) {
        const int n = int(parse_int_value(flag, value, 1, 32768));
        return {n, n};
    }
    if (value.find('x', x + 1) != std::string::npos || x == 0 || x + 1 == value.size())
        throw UsageError(flag + ": expected WxH or N, got '" + value + "'");
    // The width or height alone is named in the message, with the whole value beside it.
    const auto side = [&](const std::string& part, const char* name) {
        try {
            return int(parse_int_value(flag, part, 1, 32768));
        } catch (const UsageError&) {
            throw UsageError(flag + ": the " + name + " must be an integer in 1..32768, got '" + part +
                             "' in '" + value + "'");
        }
    };
    return {side(value.substr(0, x), "width"), side(value.substr(x + 1), "height")};
}

CLI::Option* add_threads_option(CLI::App& app, int& threads) {
    return app.add_option_function<std::string>("--threads", [&threads](const std::string& v) {
        threads = int(parse_int_value("--threads", v, 1, 1024));
    });
}

CLI::Option* add_size_option(CLI::App& app, std::optional<int>& width, std::optional<int>& height) {
    return app.add_option_function<std::string>("--size", [&width, &height](const std::string& v) {
        const auto [w, h] = parse_size_value("--size", v);
        width = w;
        height = h;
    });
}

namespace {

/// Adds `flag` whose value `parse(flag, value)` checks and converts into `target`.
template <class T, class Parse>
void add_parsed(CLI::App& app, const std::string& flag, std::optional<T>& target, Parse parse) {
    app.add_option_function<std::string>(
        flag, [&target, flag, parse](const std::string& v) { target = parse(flag, v); });
}

auto int_in(long long lo, long long hi) {
    return [lo, hi](const std::string& flag, const std::string& v) {
        return int(parse_int_value(flag, v, lo, hi));
    };
}

auto real_in(double lo, double hi) {
    return
        [lo, hi](const std::string& flag, const std::string& v) { return parse_real_value(flag, v, lo, hi); };
}

}  // namespace

namespace {

IntegratorType parse_integrator_name(const std::string& flag, const std::string& v) {
    if (v == "path") return IntegratorType::path;
    if (v == "whitted") return IntegratorType::whitted;
    if (v == "albedo") return IntegratorType::albedo;
    if (v == "normals") return IntegratorType::normals;
    if (v == "depth") return IntegratorType::depth;
    if (v == "bvh-cost") return IntegratorType::bvh_cost;
    throw UsageError(flag + ": expected path|whitted|albedo|normals|depth|bvh-cost, got '" + v + "'");
}

SamplerType parse_sampler_name(const std::string& flag, const std::string& v) {
    if (v == "sobol") return SamplerType::sobol;
    if (v == "independent") return SamplerType::independent;
    throw UsageError(flag + ": expected sobol|independent, got '" + v + "'");
}

}  // namespace

BvhBuilder parse_builder_name(const std::string& flag, const std::string& v) {
    BvhBuilder b{};
    if (!parse_bvh_builder(v, b))
        throw UsageError(flag + ": expected binned|sweep|reinsert|sbvh|auto, got '" + v + "'");
    return b;
}

BvhLayout parse_layout_name(const std::string& flag, const std::string& v) {
    BvhLayout l{};
    if (!parse_bvh_layout(v, l))
        throw UsageError(flag + ": expected " + std::string(kBvhLayoutChoices) + ", got '" + v + "'");
    return l;
}

void add_render_flags(CLI::App& app, RenderOverrides& o) {
    add_parsed(app, "--spp", o.spp, int_in(1, 1 << 24));
    add_parsed(app, "--width", o.width, int_in(1, 32768));
    add_parsed(app, "--height", o.height, int_in(1, 32768));
    add_size_option(app, o.width, o.height);
    add_parsed(app, "--max-depth", o.max_depth, int_in(1, 1024));  // the scene file's render.max_depth range
    add_parsed(app, "--seed", o.seed, parse_uint64_value);
    add_parsed(app, "--integrator", o.integrator, parse_integrator_name);
    add_parsed(app, "--time", o.time_limit_s, real_in(0.0, 1e9));
    add_parsed(app, "--target-error", o.target_error, real_in(1e-6, 1e3));
    add_parsed(app, "--builder", o.bvh_builder, parse_builder_name);
    add_parsed(app, "--layout", o.bvh_layout, parse_layout_name);
    add_parsed(app, "--sampler", o.sampler, parse_sampler_name);
    app.add_flag_callback("--no-packets", [&o] { o.packets = false; });
    add_parsed(app, "--exposure", o.exposure, [](const std::string& flag, const std::string& v) {
        return float(parse_real_value(flag, v, -64.0, 64.0));
    });
    add_parsed(app, "--tonemap", o.tonemap, [](const std::string& flag, const std::string& v) {
        const std::optional<Tonemap> t = tonemap_from_name(v);
        if (!t) throw UsageError(flag + ": expected clamp|reinhard|aces|filmic, got '" + v + "'");
        return *t;
    });
}

}  // namespace sahara
