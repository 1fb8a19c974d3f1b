#pragma once
/// The C++ side of sahara.RayCaster: one triangle mesh, its wide8 BVH (the
/// renderer's Accelerator) and the batch queries the bindings run with the GIL
/// released, OpenMP over the rays.
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/hit.h"
#include "math/vec3.h"
#include "python/raycast_arrays.h"

namespace sahara {
class Accelerator;
}

namespace sahara::python {

/// Nearest-hit results, one entry per ray (caller-owned storage).
struct NearestHits {
    float* t;       ///< inf on a miss
    int64_t* prim;  ///< -1 on a miss
    float* uv;      ///< 2 per ray; 0 on a miss
    float* normal;  ///< 3 per ray, unit geometric normal (counter-clockwise front); 0 on a miss
};

/// Every crossing of a batch, sorted by ray then t, collected per chunk of rays
/// (so the caller can allocate the result arrays once it knows the total).
struct Crossings {
    std::vector<std::vector<Hit>> hits;        ///< per chunk
    std::vector<std::vector<int64_t>> ray_of;  ///< per chunk, the ray of each hit
    std::vector<size_t> offset;                ///< per chunk, its first hit in the result; then the total

    size_t total() const { return offset.empty() ? 0 : offset.back(); }
    /// Fills the flat result arrays (total() entries, uv 2 per entry).
    void write(int64_t* ray, int64_t* prim, float* t, float* uv) const;
};

class CastMesh {
   public:
    /// Builds the BVH (OpenMP inside); `positions` and `indices` are kept for normals.
    CastMesh(std::vector<Vec3> positions, std::vector<uint32_t> indices);
    ~CastMesh();
    CastMesh(const CastMesh&) = delete;
    CastMesh& operator=(const CastMesh&) = delete;

    void nearest(const RayBatch& rays, const NearestHits& out) const;
    void occluded(const RayBatch& rays, bool* out) const;
    void count_crossings(const RayBatch& rays, int32_t* out) const;
    Crossings crossings(const RayBatch& rays) const;

    const std::vector<Vec3>& positions() const { return positions_; }
    const std::vector<uint32_t>& indices() const { return indices_; }
    size_t triangle_count() const { return indices_.size() / 3; }
    /// Bytes of the BVH and its leaf triangles.
    size_t bvh_bytes() const;

   private:
    Vec3 unit_normal(uint32_t triangle) const;
    /// Writes ray k's entry of `out` (a miss when !hit.hit()).
    void store(size_t k, const Hit& hit, const NearestHits& out) const;

    std::vector<Vec3> positions_;
    std::vector<uint32_t> indices_;
    std::unique_ptr<Accelerator> accel_;
};

}  // namespace sahara::python
