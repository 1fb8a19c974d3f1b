#pragma once
/// Tracing whole ray sets in parallel, timing them, and comparing the answers
/// of sahara and Embree ray by ray (used by `sahara bench` and its tests).
#include <cstdint>
#include <vector>

#include "scene/accelerator.h"
#include "accel/embree_reference.h"
#include "desc/scene_desc.h"

namespace sahara {

/// Per-ray answers of one pass: t (+inf on a miss) and triangle index (kNoPrim on a miss).
/// For occlusion passes t is 0 (occluded) or +inf.
struct RayAnswers {
    std::vector<float> t;
    std::vector<uint32_t> prim;
    size_t hits() const;
};

/// Duration of one pass over a ray set.
struct PassTime {
    double wall_s = 0;  ///< elapsed time
    double cpu_s = 0;   ///< CPU time summed over the tracing threads (robust when cores are shared)
};

/// Traces `rays` with sahara on `threads` threads (FTZ/DAZ as given).
PassTime trace_sahara(const Accelerator& accel, const std::vector<Ray>& rays, bool occlusion, int threads,
                      bool ftz, RayAnswers& out);
/// Occlusion rays through Accelerator::occluded with one OcclusionCache per thread
/// (the shadow cache; the renderer keeps one per light and thread).
PassTime trace_sahara_cached(const Accelerator& accel, const std::vector<Ray>& rays, int threads, bool ftz,
                             RayAnswers& out);
/// The same with Embree's rtcIntersect1 / rtcOccluded1.
PassTime trace_embree(const EmbreeReference& embree, const std::vector<Ray>& rays, bool occlusion,
                      int threads, bool ftz, RayAnswers& out);

/// Traces row-major `width` x `height` camera rays as 16-ray packets of 4x4
/// pixel tiles (Accelerator::intersect_packet; edge tiles have inactive lanes).
PassTime trace_sahara_packets(const Accelerator& accel, const std::vector<Ray>& rays, int width, int height,
                              int threads, bool ftz, RayAnswers& out);
/// The same tiles with Embree's rtcIntersect16.
PassTime trace_embree_packets(const EmbreeReference& embree, const std::vector<Ray>& rays, int width,
                              int height, int threads, bool ftz, RayAnswers& out);

struct Disagreements {
    size_t total = 0;  ///< hit/miss differ, t differs beyond tolerance, or another primitive at a different t
    size_t ties = 0;   ///< another primitive at t equal within 1e-6 relative (not counted in total)
    /// Differences where a double-precision brute-force test over all triangles
    /// sides with `a` (not counted in total). Embree's default triangle test is
    /// not watertight: rays slip through shared edges and hit something farther.
    size_t confirmed_for_a = 0;
};

/// Compares two passes (answers: triangle indices) over the same `rays` of `mesh`.
/// t tolerance: 1e-4 relative plus 1e-6 of the origin's magnitude in units of |dir|
/// (float cannot resolve a smaller t near the start of a ray far from the origin).
Disagreements compare_answers(const RayAnswers& a, const RayAnswers& b, const std::vector<Ray>& rays,
                              const TriangleMesh& mesh);

/// Nearest hit distance of `ray` over all triangles of `mesh` in double precision
/// (Moller-Trumbore, barycentrics >= 0, t in (tmin, tmax)); +inf on a miss. Slow: for arbitration only.
double nearest_hit_double(const Ray& ray, const TriangleMesh& mesh);

}  // namespace sahara
