#pragma once
// A small curved grid with normals and uvs, the source mesh of the compressed
// glTF tests, and a corner-by-corner comparison of two loaded meshes (a
// compressor may renumber vertices, so indices are compared through what they
// point at).
#include <algorithm>
#include <cmath>
#include <vector>

#include "gltf_test_doc.h"

namespace sahara::test::gltf {

struct GridMesh {
    std::vector<float> positions, normals, uvs;
    std::vector<uint32_t> indices;
    size_t vertices() const { return positions.size() / 3; }
};

/// `n` x `n` quads over [0,1]^2, z a gentle bump, normals of that surface.
inline GridMesh grid_mesh(int n = 4) {
    GridMesh g;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) {
            const float u = float(x) / float(n), v = float(y) / float(n);
            const float z = 0.25f * std::sin(3.0f * u) * std::cos(2.0f * v);
            const float dzdu = 0.75f * std::cos(3.0f * u) * std::cos(2.0f * v);
            const float dzdv = -0.5f * std::sin(3.0f * u) * std::sin(2.0f * v);
            const float len = std::sqrt(dzdu * dzdu + dzdv * dzdv + 1.0f);
            g.positions.insert(g.positions.end(), {u, v, z});
            g.normals.insert(g.normals.end(), {-dzdu / len, -dzdv / len, 1.0f / len});
            g.uvs.insert(g.uvs.end(), {u, 1.0f - v});
        }
    const auto at = [n](int x, int y) { return uint32_t(y * (n + 1) + x); };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            g.indices.insert(g.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y),
                                               at(x + 1, y + 1), at(x, y + 1)});
    return g;
}

/// The grid as an uncompressed one-primitive glTF document.
inline Doc plain_grid_doc(const GridMesh& g) {
    Doc d;
    const int pos = d.positions(g.positions);
    const int nrm = d.accessor(g.normals, 5126, "VEC3", g.vertices());
    const int uv = d.accessor(g.uvs, 5126, "VEC2", g.vertices());
    const int idx = d.accessor(g.indices, 5125, "SCALAR", g.indices.size());
    d.node({{"mesh", d.mesh(pos, idx, 4, {{"NORMAL", nrm}, {"TEXCOORD_0", uv}})}});
    return d;
}

/// Checks that `got` has the triangles of `want`, corner by corner, with
/// positions, normals and uvs equal within `pos_tol`, `nrm_tol` and `uv_tol`.
inline void check_same_corners(const TriangleMesh& got, const TriangleMesh& want, float pos_tol,
                               float nrm_tol, float uv_tol) {
    REQUIRE(got.indices.size() == want.indices.size());
    REQUIRE(got.normals.size() == got.positions.size());
    REQUIRE(got.uvs.size() == got.positions.size());
    float pos_err = 0, nrm_err = 0, uv_err = 0;
    for (size_t c = 0; c < want.indices.size(); ++c) {
        const uint32_t a = got.indices[c], b = want.indices[c];
        for (int k = 0; k < 3; ++k) {
            pos_err = std::max(pos_err, std::abs(got.positions[a][k] - want.positions[b][k]));
            nrm_err = std::max(nrm_err, std::abs(got.normals[a][k] - want.normals[b][k]));
        }
        uv_err = std::max(
            {uv_err, std::abs(got.uvs[a].x - want.uvs[b].x), std::abs(got.uvs[a].y - want.uvs[b].y)});
    }
    CHECK(pos_err <= pos_tol);
    CHECK(nrm_err <= nrm_tol);
    CHECK(uv_err <= uv_tol);
}

}  // namespace sahara::test::gltf
