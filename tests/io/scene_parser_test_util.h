#pragma once
/// Shared helpers of the scene parser tests: a scratch directory, loaders
/// that record their calls, and message checks.
#include <doctest/doctest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "io/scene_parser.h"

namespace sahara::parser_test {

namespace fs = std::filesystem;

/// A scratch directory with empty stand-in files for textures, meshes and the envmap.
struct ScratchDir {
    fs::path dir;
    ScratchDir() {
        dir = fs::temp_directory_path() / ("sahara_parser_test_" + std::to_string(::getpid()));
        fs::create_directories(dir / "textures");
        fs::create_directories(dir / "meshes");
        for (const char* f : {"textures/wood.png", "textures/leaf.png", "sky.exr", "meshes/thing.obj"})
            std::ofstream(dir / f) << "x";
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

/// Loaders that record their calls instead of reading files.
struct FakeLoaders {
    std::vector<std::pair<std::string, bool>> images;
    std::vector<Mat4> model_transforms;
    SceneLoaders loaders() {
        SceneLoaders l;
        l.read_image = [this](const fs::path& f, bool srgb) {
            images.emplace_back(f.filename().string(), srgb);
            auto img = std::make_shared<Image>();
            img->width = srgb ? 1 : 2;
            return std::shared_ptr<const Image>(img);
        };
        l.load_model = [this](const fs::path&, const Mat4& m, const std::optional<std::string>&) {
            model_transforms.push_back(m);
            LoadedModel model;
            TriangleMesh mesh;
            mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
            mesh.indices = {0, 1, 2, 1, 3, 2};
            mesh.material_ids = {0, 1};
            model.meshes.push_back(mesh);
            MaterialDesc a, b;
            a.name = "model-a";
            a.albedo.kind = ColorSource::Kind::texture;
            a.albedo.texture = 0;
            b.name = "model-b";
            b.alpha_texture = 0;
            model.materials = {a, b};
            model.textures.push_back(TextureDesc{});
            model.lights.push_back(LightDesc{});
            return model;
        };
        return l;
    }
};

inline const char* kMinimal = R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0]}, "objects": []})";

/// The InputError message of parsing `json` as "dir/bad.json", or "" when it parses.
inline std::string error_of(const std::string& json) {
    FakeLoaders fake;
    ScratchDir scratch;
    try {
        parse_scene_json(json, scratch.dir / "bad.json", fake.loaders());
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// A minimal scene with `objects` (JSON array text) and `materials` (object text).
inline std::string with_objects(const std::string& objects, const std::string& materials = "{}") {
    return R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1, 0]}, "materials": )" + materials +
           R"(, "objects": )" + objects + "}";
}

inline void check_contains(const std::string& msg, const std::vector<std::string>& fragments) {
    CAPTURE(msg);
    CHECK(msg.find("bad.json") != std::string::npos);
    for (const auto& f : fragments) {
        CAPTURE(f);
        CHECK(msg.find(f) != std::string::npos);
    }
}

inline bool near(const Vec3& a, const Vec3& b, float eps = 1e-5f) { return length(a - b) <= eps; }

}  // namespace sahara::parser_test
