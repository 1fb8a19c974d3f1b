#pragma once
/// The BVH builder and layout a scene or the command line picks. Plain enums
/// below both accel (which implements them) and desc (whose RenderSettings
/// carries the choice), so the scene description needs nothing from accel.
/// Their names and parsers stay with the code in accel/bvh.h.
#include <cstdint>

namespace sahara {

enum class BvhBuilder : uint8_t {
    binned,     ///< binned SAH, parallel over subtrees (fast; what automatic picks unless a long render of
                ///< uneven triangles)
    sweep,      ///< exact sweep SAH over all centroid-sorted splits (quality reference)
    reinsert,   ///< binned SAH, then insertion-based reinsertion (accel/bvh_optimize.cpp)
    sbvh,       ///< object and spatial splits (accel/bvh_sbvh.cpp): triangles may be in several leaves
    automatic,  ///< "auto": binned or reinsert per scene (choose_bvh_builder in accel/bvh.h)
};

/// The builder used unless a scene ("render": {"bvh_builder"}) or --builder says otherwise.
/// Automatic: reinsertion where the render is long enough for its better tree to repay
/// the slower build and a few huge triangles (walls, floors) spoil top-down splits,
/// binned otherwise (the rule and its measurements: docs/performance.md).
inline constexpr BvhBuilder kDefaultBvhBuilder = BvhBuilder::automatic;

/// Traversal structure built from the binary SAH tree (scene/accelerator.h).
enum class BvhLayout : uint8_t {
    pairs,  ///< binary tree, both child boxes per node block (accel/bvh_pairs.h): the reference
    wide8,  ///< 8-wide BVH (accel/bvh_wide.h, AVX box test), leaf triangles in SSE blocks of 4
};

/// The layout used unless --layout says otherwise (render, view, bench, bvh).
inline constexpr BvhLayout kDefaultBvhLayout = BvhLayout::wide8;

}  // namespace sahara
