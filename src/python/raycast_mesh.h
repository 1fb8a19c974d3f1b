#pragma once
/// The C++ side of sahara.RayCaster: one triangle mesh, its wide8 BVH (the
/// renderer's Accelerator) and the batch queries the bindings run with the GIL
/// released, OpenMP over the rays.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "geometry/hit.h"
#include "math/vec3.h"
#include "python/ray_order.h"
#include "python/raycast_arrays.h"

namespace sahara {
class Accelerator;
}

namespace sahara::python {

/// The most a caster keeps of its sort buffers between batches: those of about 1.8
/// million rays (72 bytes per ray); larger batches allocate theirs each time.
inline constexpr size_t kMaxKeptSortBytes = size_t(128) << 20;

/// Nearest-hit results, one entry per ray (caller-owned storage).
struct NearestHits {
    float* t;       ///< inf on a miss
    int64_t* prim;  ///< -1 on a miss
    float* uv;      ///< 2 per ray; 0 on a miss
    float* normal;  ///< 3 per ray, unit geometric normal (counter-clockwise front); 0 on a miss
};

/// The rays [first, last) of a batch, run on `threads` OpenMP threads (0: OpenMP's
/// default, all cores). The bindings cast a long batch as a series of slices so
/// that Python's signal handlers (Ctrl-C) run between them.
struct RaySlice {
    size_t first = 0;
    size_t last = 0;
    int threads = 0;
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

    /// The order to trace a batch in: its own when it is short or its runs are already
    /// coherent (a camera's rays), otherwise sorted (ray_order), which keeps neighbouring
    /// rays on the same nodes, in the buffers the last batch left (recycle). OpenMP on
    /// `threads` (0: all).
    TraceOrder trace_order(const RayBatch& rays, int threads) const;
    /// Keeps the buffers of a finished order for the next batch, up to kMaxKeptSortBytes
    /// (the larger of two concurrent batches' buffers wins).
    void recycle(TraceOrder&& order) const;
    /// Positions [slice.first, slice.last) of `rays`; results go to each ray's batch index.
    /// With a sorted order the hits wait in rays.hits until write_sorted_hits.
    void nearest(TraceOrder& rays, RaySlice slice, const NearestHits& out) const;
    void write_sorted_hits(const TraceOrder& rays, int threads, const NearestHits& out) const;
    void occluded(const TraceOrder& rays, RaySlice slice, bool* out) const;
    void count_crossings(const RayBatch& rays, int32_t* out) const;
    Crossings crossings(const RayBatch& rays) const;

    const std::vector<Vec3>& positions() const { return positions_; }
    const std::vector<uint32_t>& indices() const { return indices_; }
    size_t triangle_count() const { return indices_.size() / 3; }
    /// Bytes of the BVH and its leaf triangles.
    size_t bvh_bytes() const;
    /// Threads of the queries that do not name their own (0: all).
    int threads() const { return threads_; }
    void set_threads(int threads) { threads_ = threads; }
    /// Rays per second and thread of the last batch (0: none yet), which sizes the next
    /// batch's first slice between signal checks.
    double slice_rate() const { return slice_rate_.load(std::memory_order_relaxed); }
    void set_slice_rate(double rate) const { slice_rate_.store(rate, std::memory_order_relaxed); }

   private:
    /// What a hit needs of its triangle, in one 16-byte row: the unit normal, and the
    /// distance along the ray below which the test's t may be off by more than a few
    /// float roundings and refine() recomputes it.
    struct TriangleFacts {
        Vec3 normal;
        float refine_below;
    };
    TriangleFacts facts(uint32_t triangle) const;
    /// Whether a hit at `distance` along its ray (t times the direction's length) on
    /// `triangle` is near enough for refine to change it.
    bool needs_refine(float distance, uint32_t triangle) const {
        return distance < facts_[triangle].refine_below;
    }
    /// Replaces the t and barycentrics of `hit` on `ray` (the ray as cast, before the
    /// traversal shortened it) by the plane intersection of its triangle in double,
    /// when the hit is nearer than the triangle's refine_below.
    void refine(const Ray& ray, Hit& hit) const;
    /// nearest() of a sorted order: its contiguous rays, hits kept in sorted order.
    void nearest_sorted(TraceOrder& rays, RaySlice slice) const;
    /// The largest origin spread of a packet the packet traversal takes.
    float packet_max_offset() const;
    /// Of every triangle, computed once: a hit then reads one row instead of three
    /// indices and three vertices.
    std::vector<TriangleFacts> facts_;
    /// Writes ray k's entry of `out` (a miss when !hit.hit()).
    void store(size_t k, const Hit& hit, const NearestHits& out) const;

    std::vector<Vec3> positions_;
    std::vector<uint32_t> indices_;
    std::unique_ptr<Accelerator> accel_;
    int threads_ = 0;
    /// Sort buffers between batches (trace_order, recycle); casts run concurrently
    /// from Python threads, each taking the buffers or, when another has them, new ones.
    mutable std::mutex spare_mutex_;
    mutable SortBuffers spare_;
    mutable std::atomic<double> slice_rate_{0.0};
};

}  // namespace sahara::python
