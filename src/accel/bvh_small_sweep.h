#pragma once
/// The binned builder's split of short ranges (bvh_small_sweep.cpp): an exact SAH sweep
/// over the primitives sorted by centroid on each axis. Near the leaves a range holds a
/// few primitives, where bins cost more to clear and search than the primitives they
/// sort, and where every bin boundary is also a boundary between two primitives in
/// centroid order: the sweep sees every split the bins see, and more. Internal to accel.
#include "accel/bvh_bins.h"

namespace sahara::binned {

/// Longest range the sweep takes (BvhBuildParams::sweep_max_prims is clamped to it).
inline constexpr uint32_t kSweepMaxPrims = 16;

/// The cheapest split of a short range: the first left_count primitives in centroid
/// order on `axis`. Its cost is the intersection term, as BinSplit's.
struct SweepSplit {
    int axis = -1;  ///< < 0: no split with a finite cost
    uint32_t left_count = 0;
    float cost = kInfinity;
};

/// The centroid orders of refs[0, n), n <= kSweepMaxPrims, and the sweep over them.
class SmallSweep {
   public:
    SmallSweep(const PrimRef* refs, uint32_t n);
    /// The cheapest split over all three axes; ties go to the lower axis, then to
    /// fewer primitives on the left. None (axis < 0) when a centroid is NaN.
    SweepSplit best(const SplitCosts& costs) const;
    /// Reorders refs (the same n primitives) into the split's order and returns the
    /// boxes and centroid bounds of both sides.
    void apply(PrimRef* refs, const SweepSplit& s, Box4& left_box, Box4& right_box, Box4& left_centroids,
               Box4& right_centroids) const;

   private:
    uint32_t n_;
    bool valid_ = true;
    uint8_t order_[3][kSweepMaxPrims];  ///< order_[axis][k]: index of the k-th smallest centroid
    __m128 lo_[kSweepMaxPrims], hi_[kSweepMaxPrims];
};

}  // namespace sahara::binned
