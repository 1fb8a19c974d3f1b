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

namespace sahara::test {

/// A fresh directory per test, removed afterwards.
struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& name)
        : path(std::filesystem::temp_directory_path() /
               ("sahara_test_" + std::to_string(::getpid()) + "_" + name)) {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    /// The path of `file` in the directory.
    std::string operator/(const std::string& file) const { return (path / file).string(); }
};

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
