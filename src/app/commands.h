#pragma once
/// The subcommands of `sahara`; each returns the process exit code.
#include <string>
#include <vector>

namespace sahara {

/// `sahara render`: arguments after the command name.
int run_render_command(const std::vector<std::string>& args);

}  // namespace sahara
