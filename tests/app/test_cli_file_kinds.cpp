// Every command decides a file's kind by its extension whatever its case
// (io/files.h): MODEL.OBJ, Scene.GLB and SCENE.JSON work like their lower-case names.
#include <doctest/doctest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_data.h"

namespace fs = std::filesystem;
using sahara::test::kTestData;

namespace {

struct KindsDir {
    fs::path path = fs::temp_directory_path() / ("sahara_kinds_" + std::to_string(::getpid()));
    KindsDir() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~KindsDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

struct KindsRun {
    int code = -1;
    std::string out, err;
};

/// Runs `sahara ARGS` in `dir`, capturing stdout and stderr.
KindsRun run_in(const KindsDir& dir, const std::string& args) {
    const fs::path out = dir.path / "stdout.txt", err = dir.path / "stderr.txt";
    const std::string cmd = "cd " + dir.path.string() + " && " + SAHARA_EXE + " " + args + " >" +
                            out.string() + " 2>" + err.string();
    const int status = std::system(cmd.c_str());
    auto text = [](const fs::path& p) {
        std::stringstream ss;
        ss << std::ifstream(p).rdbuf();
        return ss.str();
    };
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text(out), text(err)};
}

}  // namespace

TEST_CASE("cli: upper-case extensions work in every command") {
    KindsDir dir;
    fs::copy_file(kTestData / "obj/spot/spot.obj", dir.path / "MODEL.OBJ");
    fs::copy_file(kTestData / "gltf/Box/glTF-Binary/Box.glb", dir.path / "Scene.GLB");
    std::ofstream(dir.path / "SCENE.JSON")
        << R"({"format": "scene/1", "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "vfov": 40},
              "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]})";
    for (const char* args :
         {"info MODEL.OBJ", "info Scene.GLB", "info SCENE.JSON", "bvh MODEL.OBJ --size 8",
          "bvh Scene.GLB --size 8", "bvh SCENE.JSON --size 8",
          "bench Scene.GLB --size 8 --repeat 1 --no-embree", "bench SCENE.JSON --size 8 --repeat 1",
          "view Scene.GLB --size 8 --spp 1 -q -o VIEW.PNG",
          "render SCENE.JSON --size 8 --spp 1 -q -o OUT.EXR",
          "converge SCENE.JSON --size 8 --max-spp 2 --budget 1 -o conv"}) {
        INFO("sahara " << args);
        const KindsRun r = run_in(dir, args);
        INFO(r.err);
        CHECK(r.code == 0);
    }
    CHECK(fs::exists(dir.path / "VIEW.PNG"));
    CHECK(fs::exists(dir.path / "OUT.EXR"));
    CHECK_FALSE(fs::exists(dir.path / "OUT.EXR.partial.exr"));  // an EXR output is its own partial file
    // The same mesh read as MODEL.OBJ and as model.obj: the same tree.
    fs::copy_file(dir.path / "MODEL.OBJ", dir.path / "model.obj");
    const auto upper = nlohmann::json::parse(run_in(dir, "bvh MODEL.OBJ --json").out);
    const auto lower = nlohmann::json::parse(run_in(dir, "bvh model.obj --json").out);
    for (const char* key : {"primitives", "nodes", "leaves", "sah_cost"}) CHECK(upper[key] == lower[key]);
    // A model given to render or converge points to `sahara view`.
    for (const char* cmd : {"render", "converge"}) {
        const KindsRun r = run_in(dir, std::string(cmd) + " MODEL.OBJ --size 8");
        CHECK(r.code == 2);
        CHECK(r.err.find("MODEL.OBJ: a model, not a scene file (`sahara view MODEL.OBJ`") !=
              std::string::npos);
    }
    // trace indexes OBJ triangles only, whatever the case of a glTF or scene extension.
    for (const char* file : {"Scene.GLB", "SCENE.JSON"}) {
        const KindsRun r = run_in(dir, std::string("trace ") + file + " --rays x.rays --hits x.hits");
        CHECK(r.code == 2);
        CHECK(r.err.find("OBJ meshes only") != std::string::npos);
    }
}
