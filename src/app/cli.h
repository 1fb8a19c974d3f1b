#pragma once
/// Entry point of the `sahara` command line: dispatches subcommands.
namespace sahara {

/// Runs the CLI; returns the process exit code (0 ok, 2 bad input or usage).
int run_cli(int argc, char** argv);

}  // namespace sahara
