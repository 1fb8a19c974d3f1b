#pragma once
/// Helpers for the tests that run the built executable (SAHARA_EXE): a fresh
/// directory per test and a run that captures the exit code, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scratch_dir.h"

namespace sahara::test {

/// What a run of the executable left: its exit code and output.
struct CliRun {
    int code = -1;  ///< -1: it did not exit normally
    std::string out, err;
};

/// The whole file as text ("" if it cannot be read).
inline std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Runs `[ENV] sahara ARGS` through the shell from `dir`, capturing stdout and
/// stderr in files there.
inline CliRun run_sahara(const std::string& args, const TempDir& dir, const std::string& env = "") {
    const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string cmd =
        "cd " + dir.path.string() + " && " + env + " " + SAHARA_EXE + " " + args + " >" + out + " 2>" + err;
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(out), read_text(err)};
}

}  // namespace sahara::test
