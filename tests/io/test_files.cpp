// The one whole-file reader and the one extension check (io/files.h).
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "base/error.h"
#include "io/files.h"
#include "io/image_io.h"
#include "io/model_loader.h"

using namespace sahara;
namespace fs = std::filesystem;

namespace {

struct FilesDir {
    fs::path path = fs::temp_directory_path() / ("sahara_files_" + std::to_string(::getpid()));
    FilesDir() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~FilesDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::string message_of(const fs::path& file, const std::string& what) {
    try {
        read_file(file, what);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("file_kind decides by extension whatever its case") {
    CHECK(file_kind("scene.json") == FileKind::scene);
    CHECK(file_kind("dir.v2/SCENE.JSON") == FileKind::scene);
    CHECK(file_kind("MODEL.OBJ") == FileKind::obj);
    CHECK(file_kind("model.Obj") == FileKind::obj);
    CHECK(file_kind("a.gltf") == FileKind::gltf);
    CHECK(file_kind("Scene.GLB") == FileKind::gltf);
    CHECK(file_kind("OUT.PNG") == FileKind::png);
    CHECK(file_kind("out.Exr") == FileKind::exr);
    CHECK(file_kind("sky.HDR") == FileKind::hdr);
    CHECK(file_kind("x.pfm") == FileKind::pfm);
    CHECK(file_kind("notes.txt") == FileKind::other);
    CHECK(file_kind("obj") == FileKind::other);  // a name, not an extension
    CHECK(file_kind(".obj.bak") == FileKind::other);
    CHECK(lower_extension("A/B.GlTf") == ".gltf");
    CHECK(lower_extension("noext") == "");
    CHECK(is_model_kind(file_kind("M.GLB")));
    CHECK_FALSE(is_model_kind(file_kind("m.json")));
    // The output check and the model loader use the same decision.
    CHECK(is_supported_output("OUT.EXR"));
    CHECK(is_hdr_output("OUT.EXR"));
    CHECK_FALSE(is_hdr_output("OUT.PNG"));
    CHECK_FALSE(is_supported_output("out.jpg"));
    CHECK_THROWS_WITH_AS(load_model("thing.ply"), doctest::Contains("unknown model format '.ply'"),
                         InputError);
}

TEST_CASE("read_file returns every byte and names the file when it cannot") {
    FilesDir dir;
    const fs::path file = dir.path / "data.bin";
    const std::string bytes("a\0b\r\n\xff", 6);
    std::ofstream(file, std::ios::binary) << bytes;
    CHECK(read_file(file) == bytes);
    const std::vector<unsigned char> raw = read_file_bytes(file);
    CHECK(std::string(raw.begin(), raw.end()) == bytes);
    std::ofstream(dir.path / "empty.txt").close();
    CHECK(read_file(dir.path / "empty.txt").empty());

    const fs::path missing = dir.path / "missing.json";
    CHECK(message_of(missing, "") == missing.string() + ": no such file");
    CHECK(message_of(missing, "scene file") == missing.string() + ": cannot open scene file: no such file");
    CHECK(message_of(dir.path, "") == dir.path.string() + ": is a directory, not a regular file");
    CHECK_THROWS_AS(read_file_bytes(missing), InputError);
    if (::geteuid() != 0) {  // root reads anything
        const fs::path locked = dir.path / "locked.txt";
        std::ofstream(locked) << "x";
        fs::permissions(locked, fs::perms::none);
        CHECK(message_of(locked, "ray file").find(locked.string() + ": cannot open ray file: ") == 0);
    }
}
