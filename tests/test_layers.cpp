// The folders under src/ are layers: each includes only the folders before it
// (docs/architecture.md). A compiler does not notice an include that runs upward
// or sideways, so this test reads every source and checks each
// `#include "folder/..."` against the table below.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

/// What each folder may include besides itself.
const std::map<std::string, std::set<std::string>>& allowed_includes() {
    static const std::map<std::string, std::set<std::string>> table = {
        {"math", {}},
        {"base", {"math"}},
        {"geometry", {"math", "base"}},
        {"accel", {"math", "base", "geometry"}},
        {"desc", {"math", "base"}},
        {"io", {"math", "base", "geometry", "desc"}},
        {"scene", {"math", "base", "geometry", "accel", "desc"}},
        {"render", {"math", "base", "geometry", "desc", "scene"}},
        {"pipeline", {"math", "base", "geometry", "accel", "desc", "io", "scene", "render"}},
        {"app", {"math", "base", "geometry", "accel", "desc", "io", "scene", "render", "pipeline"}},
        // The Python module binds the library, never the command line.
        {"python", {"math", "base", "geometry", "accel", "desc", "io", "scene", "render", "pipeline"}},
    };
    return table;
}

/// Where a folder may include only some headers of a folder below it: render
/// asks the Scene (scene.h) and evaluates textures (texture.h), never the
/// accelerator or the other internals of scene/.
const std::map<std::string, std::map<std::string, std::set<std::string>>>& allowed_headers() {
    static const std::map<std::string, std::map<std::string, std::set<std::string>>> table = {
        {"render", {{"scene", {"scene/scene.h", "scene/texture.h"}}}},
    };
    return table;
}

/// The path named by an `#include "folder/file"` line, or "" for any other line.
std::string included_path(const std::string& line) {
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos || line[i] != '#') return "";
    i = line.find_first_not_of(" \t", i + 1);
    if (i == std::string::npos || line.compare(i, 7, "include") != 0) return "";
    const size_t open = line.find('"', i + 7);
    if (open == std::string::npos) return "";
    const size_t slash = line.find('/', open + 1);
    const size_t close = line.find('"', open + 1);
    if (slash == std::string::npos || close == std::string::npos || slash > close) return "";
    return line.substr(open + 1, close - open - 1);
}

/// The folder named by an `#include "folder/file"` line, or "" for any other line.
std::string included_folder(const std::string& line) {
    const std::string path = included_path(line);
    return path.substr(0, path.find('/'));
}

/// Whether a file in `folder` may have the include line `line`.
bool include_allowed(const std::string& folder, const std::string& line) {
    const std::string inc = included_folder(line);
    if (inc.empty() || inc == folder) return true;
    const auto layer = allowed_includes().find(folder);
    if (layer == allowed_includes().end() || !layer->second.count(inc)) return false;
    const auto limited = allowed_headers().find(folder);
    if (limited == allowed_headers().end()) return true;
    const auto headers = limited->second.find(inc);
    return headers == limited->second.end() || headers->second.count(included_path(line)) > 0;
}

struct BadInclude {
    std::string where;  ///< src/folder/file:line
    std::string what;   ///< the include line
};

/// Every include in the files under src/ that the table does not allow, and the
/// folders under src/ that the table does not know.
std::vector<BadInclude> bad_includes(const fs::path& src) {
    std::vector<BadInclude> bad;
    const auto& table = allowed_includes();
    for (const auto& entry : fs::recursive_directory_iterator(src)) {
        if (!entry.is_regular_file()) continue;
        const fs::path rel = fs::relative(entry.path(), src);
        const std::string folder = rel.begin()->string();
        const std::string name = "src/" + rel.generic_string();
        const auto layer = table.find(folder);
        if (layer == table.end()) {
            bad.push_back({name, "a folder the layer table does not list"});
            continue;
        }
        std::ifstream in(entry.path());
        std::string line;
        for (int number = 1; std::getline(in, line); ++number)
            if (!include_allowed(folder, line)) bad.push_back({name + ":" + std::to_string(number), line});
    }
    std::sort(bad.begin(), bad.end(),
              [](const BadInclude& a, const BadInclude& b) { return a.where < b.where; });
    return bad;
}

}  // namespace

TEST_CASE("layers: an include line names its folder") {
    CHECK(included_folder("#include \"scene/scene.h\"") == "scene");
    CHECK(included_folder("  #  include \"io/plot.h\"  // why") == "io");
    CHECK(included_folder("#include <vector>").empty());
    CHECK(included_folder("#include \"packet_kernel.inc\"").empty());
    CHECK(included_folder("// #include is mentioned in \"a/b\"").empty());
}

TEST_CASE("layers: render includes from scene/ only the Scene and its textures") {
    CHECK(include_allowed("render", "#include \"scene/scene.h\""));
    CHECK(include_allowed("render", "#include \"scene/texture.h\""));
    CHECK(include_allowed("render", "#include \"render/film.h\""));
    CHECK_FALSE(include_allowed("render", "#include \"scene/accelerator.h\""));
    CHECK_FALSE(include_allowed("render", "#include \"scene/alpha_filter.h\""));
    CHECK_FALSE(include_allowed("render", "#include \"accel/bvh.h\""));
    CHECK_FALSE(include_allowed("render", "#include \"io/image_io.h\""));
    // Other layers see scene/ whole.
    CHECK(include_allowed("app", "#include \"scene/accelerator.h\""));
    CHECK_FALSE(include_allowed("scene", "#include \"render/film.h\""));
}

TEST_CASE("layers: every include under src/ runs down the layer table") {
    const fs::path src = fs::path(SAHARA_SOURCE_DIR) / "src";
    REQUIRE(fs::is_directory(src));
    const std::vector<BadInclude> bad = bad_includes(src);
    for (const BadInclude& b : bad) FAIL_CHECK(b.where << ": " << b.what << " runs against the layers");
    CHECK(bad.empty());
}

TEST_CASE("layers: library tests include no app/ header") {
    // tests/ mirrors src/; only tests/app tests commands, and the shared helpers serve all.
    const fs::path tests = fs::path(SAHARA_SOURCE_DIR) / "tests";
    REQUIRE(fs::is_directory(tests));
    int found = 0;
    for (const auto& entry : fs::recursive_directory_iterator(tests)) {
        const fs::path rel = fs::relative(entry.path(), tests);
        const std::string folder = rel.begin()->string();
        const bool shared = std::next(rel.begin()) == rel.end();  // tests/*.h, test_main.cpp
        if (!entry.is_regular_file() || folder == "app" || (!shared && !allowed_includes().count(folder)))
            continue;
        std::ifstream in(entry.path());
        std::string line;
        for (int number = 1; std::getline(in, line); ++number)
            if (included_folder(line) == "app") {
                FAIL_CHECK("tests/" << rel.generic_string() << ":" << number << ": " << line);
                ++found;
            }
    }
    CHECK(found == 0);
}
