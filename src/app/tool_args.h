#pragma once
/// Minimal flag parsing shared by the BVH tool commands (bvh, bench, trace), and
/// the one-line usage error every command prints.
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace sahara {

struct ToolArgs {
    std::vector<std::string> positional;
    std::map<std::string, std::string> values;  ///< "--name value" flags
    std::set<std::string> switches;             ///< "--name" flags
    bool help = false;

    bool has(const std::string& name) const { return values.count(name) || switches.count(name); }
    std::string value_or(const std::string& name, const std::string& fallback) const {
        auto it = values.find(name);
        return it == values.end() ? fallback : it->second;
    }
};

/// Parses argv[1..argc): flags in `with_value` take the next argument, flags in
/// `switches` take none, `--help`/`-h` sets help. Returns an error message, empty on success.
inline std::string parse_tool_args(int argc, char** argv, const std::set<std::string>& with_value,
                                   const std::set<std::string>& switches, ToolArgs& out) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--help" || a == "-h") {
            out.help = true;
        } else if (with_value.count(a)) {
            if (i + 1 >= argc) return a + ": missing value";
            out.values[a] = argv[++i];
        } else if (switches.count(a)) {
            out.switches.insert(a);
        } else if (a.size() > 1 && a[0] == '-') {
            return "unknown option '" + a + "'";
        } else {
            out.positional.push_back(a);
        }
    }
    return "";
}

/// Prints "sahara COMMAND: MESSAGE (see 'sahara COMMAND --help')" as one line on
/// stderr (COMMAND empty: the top level) and returns exit code 2. One line, not the
/// whole help text, so the mistake stays on screen.
inline int usage_error(const std::string& command, const std::string& message) {
    const std::string program = command.empty() ? "sahara" : "sahara " + command;
    std::fprintf(stderr, "%s: %s (see '%s --help')\n", program.c_str(), message.c_str(), program.c_str());
    return 2;
}

/// Parses a positive integer flag value; false if it is not one.
inline bool parse_positive_int(const std::string& text, int& out) {
    try {
        size_t used = 0;
        const long v = std::stol(text, &used);
        if (used != text.size() || v <= 0 || v > 1 << 20) return false;
        out = int(v);
        return true;
    } catch (...) {
        return false;
    }
}

}  // namespace sahara
