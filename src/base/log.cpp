#include "base/log.h"

#include <atomic>
#include <cstdio>

namespace sahara {

namespace {
std::atomic<bool> g_quiet{false};
std::atomic<int> g_warnings{0};
}  // namespace

void log_warning(const std::string& msg) {
    ++g_warnings;
    std::fprintf(stderr, "sahara: warning: %s\n", msg.c_str());
}

void log_info(const std::string& msg) {
    if (!g_quiet) std::fprintf(stderr, "sahara: %s\n", msg.c_str());
}

void set_log_quiet(bool quiet) { g_quiet = quiet; }

int warning_count() { return g_warnings; }

}  // namespace sahara
