#pragma once
/// Fixed, seeded ray sets for `sahara bvh` and `sahara bench`: primary rays
/// from a camera framing a mesh, diffuse-bounce rays from the primary hits and
/// shadow rays from the same points towards a square light above the mesh.
/// Every ray depends only on the seed and its index (same rays for any thread count).
#include <cstdint>
#include <vector>

#include "accel/accelerator.h"
#include "math/ray.h"
#include "scene/scene_desc.h"

namespace sahara {

struct BenchRaySets {
    std::vector<Ray> primary;  ///< width x height pinhole camera rays, row-major
    std::vector<Ray> diffuse;  ///< as many as primary: cosine-distributed about the facing geometric normal
    std::vector<Ray> shadow;   ///< as many as primary: towards points on the light, tmax just short of it
};

/// Builds the three sets. Diffuse and shadow ray i start at primary hit (i mod hits),
/// offset along the facing geometric normal by 1e-4 of the mesh's bounding radius
/// (a bench-only spawn offset). Without any primary hit, diffuse and shadow are empty.
BenchRaySets make_bench_rays(const TriangleMesh& mesh, const Accelerator& accel, int width, int height,
                             uint64_t seed = 1);

}  // namespace sahara
