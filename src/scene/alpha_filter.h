#pragma once
/// Cut-out (alpha-tested) triangles: the any-hit filter that traversal applies
/// to a triangle hit before accepting it. A rejected hit is as if the ray had
/// missed that triangle: it neither shortens the ray nor counts as occlusion,
/// so foliage and fences modelled as textured cards stay see-through.
///
/// Alpha is the material's constant times its texture's alpha times, for glTF
/// `vertex_alpha` materials, the interpolated COLOR_0 alpha. Materials with
/// `alpha_cutoff` (glTF MASK) pass where alpha >= cutoff; the others with
/// alpha < 1, an alpha texture or vertex alpha (glTF BLEND, OBJ d / map_d) are
/// stochastic transparency (Enderton et al., "Stochastic Transparency", 2010):
/// a hit passes when a hash of (ray origin, direction, primitive) in [0, 1) is
/// below alpha. The hash makes every answer a pure function of the ray, so
/// renders are reproducible and independent of the thread count, and the
/// closest-hit and shadow queries of one ray agree.
///
/// One-sided materials (`double_sided == false`, glTF) are no cut-outs: the
/// accelerator drops back-face hits by a per-triangle flag (one_sided_triangles),
/// which costs the fast traversals nothing when a scene has none.
///
/// Only triangles are filtered (they carry the UVs); other primitives with a
/// cut-out material stay opaque, with a warning when the filter is built.
#include <cstdint>
#include <vector>

#include "math/ray.h"
#include "math/vec3.h"
#include "desc/scene_desc.h"

namespace sahara {

class Scene;

/// A uniform number in [0, 1) from the ray and the primitive id (the stochastic test's coin).
float cutout_hash(const Ray& ray, uint32_t prim_id);

/// The alpha test of a scene's cut-out triangles. Holds copies of what it
/// reads (UVs, alpha parameters, textures), so it stays valid when the Scene moves.
class AlphaFilter {
   public:
    /// Marks a triangle that is not cut out.
    static constexpr uint32_t kOpaque = 0xFFFFFFFFu;

    AlphaFilter() = default;
    /// Collects the scene's cut-out triangles; empty() when there are none.
    explicit AlphaFilter(const Scene& scene);

    bool empty() const { return triangles_.empty(); }
    /// Number of cut-out triangles.
    size_t size() const { return triangles_.size(); }
    /// Index of triangle `tri`'s cut-out entry, or kOpaque.
    uint32_t entry_of(uint32_t tri) const { return tri < entry_.size() ? entry_[tri] : kOpaque; }
    /// Whether the hit (barycentrics u, v of cut-out entry `entry`) on primitive `prim_id` is kept.
    bool passes(uint32_t entry, const Ray& ray, uint32_t prim_id, float u, float v) const;
    /// The alpha of cut-out entry `entry` at barycentrics (u, v).
    float alpha(uint32_t entry, float u, float v) const;
    size_t bytes() const;

   private:
    /// One cut-out material: constant alpha times the optional texture's alpha.
    struct Cutout {
        float alpha = 1.0f;
        float cutoff = -1.0f;       ///< < 0: stochastic
        int texture = -1;           ///< into textures_
        bool vertex_alpha = false;  ///< also times the triangle's interpolated vertex alpha
    };
    /// One cut-out triangle: its vertex UVs, vertex alphas and its material.
    struct Triangle {
        Vec2 uv[3];
        float vertex_alpha[3];  ///< 1 where the mesh has none
        uint32_t cutout;
    };
    std::vector<uint32_t> entry_;  ///< per scene triangle: index into triangles_, or kOpaque
    std::vector<Triangle> triangles_;
    std::vector<Cutout> cutouts_;
    std::vector<TextureDesc> textures_;
};

/// Whether a material cuts holes: alpha below 1, an alpha texture or vertex alpha.
bool is_cutout_material(const MaterialDesc& m);
/// Per scene triangle: 1 where its material is one-sided (back faces invisible);
/// empty when no triangle is.
std::vector<uint8_t> one_sided_triangles(const Scene& scene);

}  // namespace sahara
