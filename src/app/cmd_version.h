#pragma once
/// `sahara --version` (or `sahara version`): the version and the optional parts
/// this build has, so a bug report or a benchmark says what binary produced it.
#include <string>

namespace sahara {

/// The text `sahara --version` prints: "sahara VERSION" first, then one line per part.
std::string version_report();

/// Prints version_report() to stdout; returns exit code 0.
int run_version_command();

}  // namespace sahara
