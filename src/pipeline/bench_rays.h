#pragma once
/// Fixed, seeded ray sets for `sahara bvh` and `sahara bench`: primary rays
/// from a camera framing a mesh (or a scene file's own camera), diffuse-bounce
/// rays from the primary hits and shadow rays from the same points towards a
/// square light above the geometry (or a scene's sun).
/// Every ray depends only on the seed and its index (same rays for any thread count).
#include <cstdint>
#include <vector>

#include "scene/accelerator.h"
#include "math/ray.h"
#include "scene/scene.h"

namespace sahara {

struct BenchRaySets {
    std::vector<Ray> primary;  ///< width x height pinhole camera rays, row-major
    std::vector<Ray> diffuse;  ///< as many as primary: cosine-distributed about the facing geometric normal
    std::vector<Ray> shadow;   ///< as many as primary: towards points on the light, tmax just short of it
};

/// Where the primary rays come from and how hit points are offset.
enum class BenchAim : uint8_t {
    /// A pinhole camera framing the accelerator's bounds from (0.4, 0.3, 1), y up;
    /// spawn offset 1e-4 of the bounding radius (meshes: one object at one scale).
    frame_bounds,
    /// scene.camera at width x height (lens centre, shutter open); shadow rays go
    /// towards the scene's first directional light (a sun), unbounded, or without
    /// one to a light above the bounds along the camera's up axis; spawn offset by the renderer's
    /// rule (geometry/spawn.h, relative to the point's magnitude), since a scene
    /// can mix small objects with a huge ground sphere.
    scene_camera,
};

/// Builds the three sets over `accel`'s primitives (built from `scene`; planes
/// are not in it and are not hit). Diffuse and shadow ray i start at primary hit
/// (i mod hits), offset along the facing geometric normal (Scene::interact, any
/// primitive kind). Without any primary hit, diffuse and shadow are empty.
BenchRaySets make_bench_rays(const Scene& scene, const Accelerator& accel, int width, int height,
                             BenchAim aim = BenchAim::frame_bounds, uint64_t seed = 1);

}  // namespace sahara
