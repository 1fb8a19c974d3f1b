#pragma once
/// The BVH builder and layout a scene or the command line picks. Plain enums
/// below both accel (which implements them) and desc (whose RenderSettings
/// carries the choice), so the scene description needs nothing from accel.
/// Their names and parsers stay with the code in accel/bvh.h.
#include <cstdint>

namespace sahara {

enum class BvhBuilder : uint8_t {
    binned,    ///< binned SAH, parallel over subtrees (fast default)
    sweep,     ///< exact sweep SAH over all centroid-sorted splits (quality reference)
    reinsert,  ///< binned SAH, then insertion-based reinsertion (accel/bvh_optimize.cpp)
};

/// The builder used unless a scene ("render": {"bvh_builder"}) or --builder says otherwise.
/// Binned: on a typical render (some 60M rays) the better trees of sweep and reinsert
/// save no more tracing time than their slower builds cost, and on shorter renders the
/// build dominates. Reinsert pays off on long renders of meshes with uneven triangle sizes.
inline constexpr BvhBuilder kDefaultBvhBuilder = BvhBuilder::binned;

/// Traversal structure built from the binary SAH tree (scene/accelerator.h).
enum class BvhLayout : uint8_t {
    pairs,  ///< binary tree, both child boxes per node block (accel/bvh_pairs.h): the reference
    wide8,  ///< 8-wide BVH (accel/bvh_wide.h, AVX box test), leaf triangles in SSE blocks of 4
};

/// The layout used unless --layout says otherwise (render, view, bench, bvh).
inline constexpr BvhLayout kDefaultBvhLayout = BvhLayout::wide8;

}  // namespace sahara
