#include "io/mesh_triangles.h"

#include <tiny_obj_loader.h>

#include <cmath>

#include "base/error.h"
#include "io/model_loader.h"

namespace sahara {

TriangleMesh read_obj_triangles(const std::filesystem::path& file) {
    const std::string name = file.string();
    if (!std::filesystem::is_regular_file(file)) throw input_error(name, "", "no such file");
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // we fan-split ourselves, in a documented order
    config.vertex_color = false;
    config.mtl_search_path = file.parent_path().string();
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(name, config))
        throw input_error(name, "", "cannot parse OBJ: " + reader.Error());
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    TriangleMesh mesh;
    mesh.name = name;
    const size_t vertex_count = attrib.vertices.size() / 3;
    mesh.positions.reserve(vertex_count);
    for (size_t i = 0; i < vertex_count; ++i) {
        const Vec3 p(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
        if (!is_finite(p)) throw input_error(name, "v #" + std::to_string(i + 1), "non-finite position");
        mesh.positions.push_back(p);
    }
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        size_t offset = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            const size_t nv = shape.mesh.num_face_vertices[f];
            auto vertex = [&](size_t k) {
                const int idx = shape.mesh.indices[offset + k].vertex_index;
                if (idx < 0 || size_t(idx) >= vertex_count)
                    throw input_error(name, "shape '" + shape.name + "' face " + std::to_string(f + 1),
                                      "vertex index out of range");
                return uint32_t(idx);
            };
            for (size_t k = 1; k + 1 < nv; ++k) {
                mesh.indices.push_back(vertex(0));
                mesh.indices.push_back(vertex(k));
                mesh.indices.push_back(vertex(k + 1));
            }
            offset += nv;
        }
    }
    return mesh;
}

TriangleMesh read_mesh_triangles(const std::filesystem::path& file) {
    const std::string ext = file.extension().string();
    if (ext != ".gltf" && ext != ".glb") return read_obj_triangles(file);
    LoadedModel model = load_model(file);
    TriangleMesh all;
    all.name = file.string();
    for (const TriangleMesh& m : model.meshes) {
        const auto base = uint32_t(all.positions.size());
        all.positions.insert(all.positions.end(), m.positions.begin(), m.positions.end());
        for (uint32_t i : m.indices) all.indices.push_back(base + i);
    }
    return all;
}

}  // namespace sahara
