#include "scene/mesh_scene.h"

namespace sahara {

Scene scene_from_mesh(const TriangleMesh& mesh) {
    Scene scene;
    scene.source = mesh.name;
    scene.triangles.positions = mesh.positions;
    scene.triangles.indices = mesh.indices;
    scene.triangles.material.assign(mesh.triangle_count(), mesh.material);
    return scene;
}

}  // namespace sahara
