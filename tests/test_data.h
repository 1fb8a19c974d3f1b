#pragma once
// The real model files the suite carries (tests/data; origins and licences in
// tests/data/SOURCES.md): the suite needs nothing outside the repository.
#include <algorithm>
#include <filesystem>
#include <vector>

#include "io/mesh_triangles.h"
#include "scene/mesh_scene.h"
#include "mesh_fixtures.h"

namespace sahara::test {

inline const std::filesystem::path kTestData = SAHARA_SOURCE_DIR "/tests/data";

/// Every .obj under tests/data/obj, sorted (a stable order for seeds and messages).
inline std::vector<std::filesystem::path> data_obj_files() {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::recursive_directory_iterator(kTestData / "obj"))
        if (e.path().extension() == ".obj") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

/// Real meshes (the OBJ files in tests/data) and the two big scan stand-ins: the
/// sizes and flaws (holes, slivers, zero-area triangles) of scanned models.
inline std::vector<TriangleMesh> realistic_meshes() {
    std::vector<TriangleMesh> meshes;
    for (const auto& f : data_obj_files()) meshes.push_back(read_obj_triangles(f));
    meshes.push_back(make_scan_mesh_70k());
    meshes.push_back(make_scan_mesh_120k());
    return meshes;
}

}  // namespace sahara::test
