#include "scene/tangents.h"

#include <cmath>

namespace sahara {

namespace {

/// Any unit vector orthogonal to n.
Vec3 orthogonal(const Vec3& n) {
    const Vec3 a = std::abs(n.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    return normalize(cross(n, a));
}

}  // namespace

std::vector<std::array<float, 4>> generate_tangents(const TriangleMesh& mesh) {
    const size_t n = mesh.positions.size();
    if (mesh.uvs.size() != n) return {};
    std::vector<Vec3> tan(n, Vec3(0.0f)), bitan(n, Vec3(0.0f)), face_normal(n, Vec3(0.0f));
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        const uint32_t i[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
        const Vec3 e1 = mesh.positions[i[1]] - mesh.positions[i[0]];
        const Vec3 e2 = mesh.positions[i[2]] - mesh.positions[i[0]];
        const float du1 = mesh.uvs[i[1]].x - mesh.uvs[i[0]].x, dv1 = mesh.uvs[i[1]].y - mesh.uvs[i[0]].y;
        const float du2 = mesh.uvs[i[2]].x - mesh.uvs[i[0]].x, dv2 = mesh.uvs[i[2]].y - mesh.uvs[i[0]].y;
        const Vec3 fn = cross(e1, e2);  // area-weighted
        const float det = du1 * dv2 - du2 * dv1;
        for (uint32_t k : i) face_normal[k] += fn;
        if (det == 0.0f || !std::isfinite(det)) continue;
        // dP/du and dP/dv of the triangle's linear map, weighted by its area.
        const float area = length(fn), inv = 1.0f / det;
        const Vec3 dpdu = (e1 * dv2 - e2 * dv1) * inv, dpdv = (e2 * du1 - e1 * du2) * inv;
        const float lu = length(dpdu), lv = length(dpdv);
        if (!(lu > 0) || !(lv > 0) || !std::isfinite(lu) || !std::isfinite(lv)) continue;
        for (uint32_t k : i) {
            tan[k] += dpdu * (area / lu);
            bitan[k] += dpdv * (area / lv);
        }
    }
    std::vector<std::array<float, 4>> out(n);
    for (size_t k = 0; k < n; ++k) {
        Vec3 nn = mesh.normals.size() == n ? mesh.normals[k] : face_normal[k];
        nn = length_squared(nn) > 0 ? normalize(nn) : Vec3(0, 0, 1);
        Vec3 t = tan[k] - nn * dot(nn, tan[k]);  // Gram-Schmidt against the normal
        t = length_squared(t) > 1e-20f ? normalize(t) : orthogonal(nn);
        const float w = dot(cross(nn, t), bitan[k]) < 0 ? -1.0f : 1.0f;
        out[k] = {t.x, t.y, t.z, w};
    }
    return out;
}

}  // namespace sahara
