#pragma once
/// The one argument parser of every command: CLI11 apps set up alike, the
/// shared value checks (ranges, WxH, names) whose messages name the option,
/// and the one-line usage error.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "desc/scene_desc.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace sahara {

struct RenderOverrides;

/// A malformed command line: the app prints the message as one line, exit 2.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Prints "sahara COMMAND: MESSAGE (see 'sahara COMMAND --help')" as one line on
/// stderr (COMMAND empty: the top level) and returns exit code 2. One line, not the
/// whole help text, so the mistake stays on screen.
int usage_error(const std::string& command, const std::string& message);

/// Sets `app` up as every command's: `-h, --help` sets `help` (the command prints
/// its own text), a repeated option keeps its last value, unknown options are
/// collected so parse_command_line can name them.
void configure_app(CLI::App& app, bool& help);

/// Parses `args` (the words after the command name) into `app`'s options and
/// returns the positional words. Throws UsageError with a one-line message:
/// "unknown option '--x'", "--spp: missing value", "--spp: expected ...".
std::vector<std::string> parse_command_line(CLI::App& app, const std::vector<std::string>& args);

/// The shared value checks; each throws UsageError naming `flag`.
long long parse_int_value(const std::string& flag, const std::string& value, long long lo, long long hi);
uint64_t parse_uint64_value(const std::string& flag, const std::string& value);
double parse_real_value(const std::string& flag, const std::string& value, double lo, double hi);
/// "WxH", or "N" for N x N; each side in 1..32768.
std::pair<int, int> parse_size_value(const std::string& flag, const std::string& value);

/// BVH builder and layout names (throw UsageError naming `flag`).
BvhBuilder parse_builder_name(const std::string& flag, const std::string& value);
BvhLayout parse_layout_name(const std::string& flag, const std::string& value);

/// `--threads N` (1..1024), the same in every command.
CLI::Option* add_threads_option(CLI::App& app, int& threads);
/// `--size WxH|N`: an image (or primary-ray grid) of W x H pixels, N x N for one number.
CLI::Option* add_size_option(CLI::App& app, std::optional<int>& width, std::optional<int>& height);

/// The render settings every rendering command takes (render, view, converge and
/// converge's --compare): --spp, --width, --height, --size, --max-depth, --seed,
/// --integrator, --time, --target-error, --builder, --layout, --sampler,
/// --no-packets, --exposure, --tonemap.
void add_render_flags(CLI::App& app, RenderOverrides& o);

}  // namespace sahara
