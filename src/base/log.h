#pragma once
/// Warnings and information for the user, always on stderr.
#include <string>

namespace sahara {

/// Prints "sahara: warning: MSG" to stderr (thread-safe, one line).
void log_warning(const std::string& msg);
/// Prints "sahara: MSG" to stderr unless quiet logging is enabled.
void log_info(const std::string& msg);
/// Silences log_info (warnings still print).
void set_log_quiet(bool quiet);
/// Number of warnings printed so far (tests use it).
int warning_count();

}  // namespace sahara
