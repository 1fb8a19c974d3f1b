#pragma once
/// Per-thread event counters for `--stats` (pbrt-style): the hot path bumps a
/// plain thread-local struct (no atomics, no allocation); each worker flushes
/// its counts into the process totals when its parallel region ends.
#include <cstdint>

namespace sahara {

/// What a traced ray was for.
enum class RayKind : uint8_t { camera, closest_hit, shadow };
inline constexpr int kRayKinds = 3;

/// Counters one thread accumulates.
struct Counters {
    uint64_t rays[kRayKinds] = {};   ///< camera rays; closest-hit queries; occlusion (shadow) queries
    uint64_t bvh_nodes_visited = 0;  ///< filled by the BVH when it records traversal steps
    uint64_t bvh_primitive_tests = 0;
    uint64_t bvh_leaves_visited = 0;

    Counters& operator+=(const Counters& o) {
        for (int k = 0; k < kRayKinds; ++k) rays[k] += o.rays[k];
        bvh_nodes_visited += o.bvh_nodes_visited;
        bvh_primitive_tests += o.bvh_primitive_tests;
        bvh_leaves_visited += o.bvh_leaves_visited;
        return *this;
    }
};

/// This thread's counters (constant-initialised: no guard on access).
inline constinit thread_local Counters t_counters{};

inline void count_ray(RayKind kind) { ++t_counters.rays[static_cast<int>(kind)]; }

/// Adds this thread's counters to the totals and zeroes them (thread-safe).
void flush_thread_counters();
/// Totals flushed so far.
Counters counter_totals();
/// Zeroes the totals (and this thread's counters).
void reset_counters();

}  // namespace sahara
