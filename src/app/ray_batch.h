#pragma once
/// Tracing whole ray sets in parallel, timing them, and comparing the answers
/// of sahara and Embree ray by ray (used by `sahara bench` and its tests).
#include <cstdint>
#include <vector>

#include "accel/accelerator.h"
#include "accel/embree_reference.h"

namespace sahara {

/// Per-ray answers of one pass: t (+inf on a miss) and triangle index (kNoPrim on a miss).
/// For occlusion passes t is 0 (occluded) or +inf.
struct RayAnswers {
    std::vector<float> t;
    std::vector<uint32_t> prim;
    size_t hits() const;
};

/// Traces `rays` with sahara on `threads` threads (FTZ/DAZ as given); returns seconds.
double trace_sahara(const Accelerator& accel, const std::vector<Ray>& rays, bool occlusion, int threads, bool ftz,
                    RayAnswers& out);
/// The same with Embree's rtcIntersect1 / rtcOccluded1.
double trace_embree(const EmbreeReference& embree, const std::vector<Ray>& rays, bool occlusion, int threads,
                    bool ftz, RayAnswers& out);

struct Disagreements {
    size_t total = 0;  ///< hit/miss differ, t beyond 1e-4 relative, or another primitive at a different t
    size_t ties = 0;   ///< another primitive at t equal within 1e-6 relative (not counted in total)
};

/// Compares two passes over the same rays. Triangle ids of the Accelerator are
/// prim ids (make_prim_id); Embree's are plain triangle indices: both are compared as indices.
Disagreements compare_answers(const RayAnswers& a, const RayAnswers& b);

}  // namespace sahara
