#pragma once
// A fresh temporary folder for a test's generated input files.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace sahara::test {

/// An empty folder `sahara_<name>_<pid>` under the system's temporary directory.
/// The process id keeps test cases that use the same name apart when ctest runs
/// them in parallel processes (one of them would otherwise delete the other's files).
inline std::filesystem::path scratch_dir(const std::string& name) {
    namespace fs = std::filesystem;
    fs::path dir = fs::temp_directory_path() / ("sahara_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// A scratch_dir that is removed when the test is done with it.
struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& name) : path(scratch_dir("test_" + name)) {}
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    /// The path of `file` in the directory.
    std::string operator/(const std::string& file) const { return (path / file).string(); }
};

}  // namespace sahara::test
