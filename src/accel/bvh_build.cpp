/// Top-down SAH builders (MacDonald and Booth, "Heuristics for ray tracing
/// using space subdivision", 1990). The binned builder is in bvh_binned.cpp.
/// The sweep builder (here) evaluates every split of the centroid-sorted
/// primitives on every axis (exact object-split SAH), O(n log^2 n); it exists
/// to measure how much quality binning gives away.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <string_view>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_binned.h"
#include "accel/bvh_sbvh.h"
#include "accel/bvh_small_sweep.h"
#include "accel/build_chunks.h"
#include "accel/build_team.h"

namespace sahara {

namespace {

using build::for_chunks;
using build::kScanChunks;

/// The chosen partition of a node's range.
struct Split {
    int axis = -1;           ///< -1: no valid split found
    uint32_t pos = 0;        ///< primitives on the left
    float cost = kInfinity;  ///< unnormalised: traversal * A + intersection * sum(A_child * n_child)
};

class BvhBuildJob {
   public:
    BvhBuildJob(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out)
        : in_(input), params_(params), out_(out) {}

    void run() {
        const auto n = uint32_t(in_.boxes.size());
        out_.prim_indices.resize(n);
        for (uint32_t i = 0; i < n; ++i) out_.prim_indices[i] = i;
        if (n == 0) return;
        out_.nodes.resize(2 * size_t(n));  // at most 2n - 1 nodes, plus the padding node
        node_count_ = Bvh::kFirstPair;
        build::with_build_team([&] { build_node(0, 0, n, 0); });
        out_.nodes.resize(out_.nodes[0].is_leaf() ? 1 : node_count_.load());
        if (out_.nodes.size() > 1) out_.nodes[1] = BvhNode{{0, 0, 0, 0, 0, 0}, 0, 0};
    }

   private:
    /// Step 1 of every node: bounds of the boxes and of the centroids in the range.
    void range_bounds(uint32_t begin, uint32_t end, Bounds3& box, Bounds3& centroids) const {
        Bounds3 boxes[kScanChunks], cents[kScanChunks];
        for_chunks(begin, end, [&](uint32_t c, uint32_t b, uint32_t e) {
            for (uint32_t i = b; i < e; ++i) {
                const uint32_t p = out_.prim_indices[i];
                boxes[c].extend(in_.boxes[p]);
                cents[c].extend(in_.centers[p]);
            }
        });
        for (uint32_t c = 0; c < kScanChunks; ++c) {
            box.extend(boxes[c]);
            centroids.extend(cents[c]);
        }
    }

    void build_node(uint32_t node_id, uint32_t begin, uint32_t end, int depth) {
        Bounds3 box, centroids;
        range_bounds(begin, end, box, centroids);
        BvhNode& node = out_.nodes[node_id];
        node.set_box(box);
        const uint32_t n = end - begin;
        const uint32_t mid = n == 1 ? begin : choose_and_partition(begin, end, box, centroids, depth);
        if (mid == begin) {
            node.index = begin;
            node.count = n;
            return;
        }
        const uint32_t first_child = node_count_.fetch_add(2);
        node.index = first_child;
        node.count = 0;
        if (n > params_.parallel_threshold) {
            // No taskwait (see BinnedBuild::build): with_build_team waits for all tasks.
#pragma omp task default(shared) firstprivate(first_child, begin, mid, depth)
            build_node(first_child, begin, mid, depth + 1);
            build_node(first_child + 1, mid, end, depth + 1);
        } else {
            build_node(first_child, begin, mid, depth + 1);
            build_node(first_child + 1, mid, end, depth + 1);
        }
    }

    /// Step 2: SAH split or leaf. Returns the split point, or `begin` for a leaf.
    uint32_t choose_and_partition(uint32_t begin, uint32_t end, const Bounds3& box, const Bounds3& centroids,
                                  int depth) {
        const uint32_t n = end - begin;
        const bool may_be_leaf = n <= params_.max_leaf_size;
        if (depth >= kBvhMedianSplitDepth) return may_be_leaf ? begin : median_split(begin, end, centroids);
        const Split split = find_sweep_split(begin, end, centroids);
        if (split.axis < 0) return may_be_leaf ? begin : median_split(begin, end, centroids);
        const float area = box.surface_area();
        const float leaf_cost = params_.intersection_cost * blocked(n) * area;
        const float split_cost = params_.traversal_cost * area + split.cost;
        if (may_be_leaf && leaf_cost <= split_cost) return begin;
        return partition_sweep(begin, end, split);
    }

    // ---- exact sweep SAH -------------------------------------------------

    void sort_range(uint32_t begin, uint32_t end, int axis) {
        std::sort(out_.prim_indices.begin() + begin, out_.prim_indices.begin() + end,
                  [&](uint32_t a, uint32_t b) {
                      const float ca = in_.centers[a][axis], cb = in_.centers[b][axis];
                      return ca < cb || (ca == cb && a < b);
                  });
    }

    Split find_sweep_split(uint32_t begin, uint32_t end, const Bounds3& centroids) {
        const uint32_t n = end - begin;
        std::vector<float> right_area(n);
        Split best;
        for (int axis = 0; axis < 3; ++axis) {
            if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
            sort_range(begin, end, axis);
            Bounds3 acc;
            for (uint32_t i = n; i-- > 1;) {
                acc.extend(in_.boxes[out_.prim_indices[begin + i]]);
                right_area[i] = acc.surface_area();
            }
            acc = Bounds3{};
            for (uint32_t i = 1; i < n; ++i) {
                acc.extend(in_.boxes[out_.prim_indices[begin + i - 1]]);
                const float cost = sah_cost(acc.surface_area(), i, right_area[i], n - i);
                if (cost < best.cost) best = Split{axis, i, cost};
            }
        }
        return best;
    }

    uint32_t partition_sweep(uint32_t begin, uint32_t end, const Split& split) {
        sort_range(begin, end, split.axis);
        return begin + split.pos;
    }

    // ---- shared ----------------------------------------------------------

    /// Unnormalised intersection term of a split's SAH cost (the traversal term is added by the caller).
    float sah_cost(float area_left, uint32_t n_left, float area_right, uint32_t n_right) const {
        return params_.intersection_cost * (area_left * blocked(n_left) + area_right * blocked(n_right));
    }

    /// Primitive count rounded up to whole leaf blocks (what a leaf of n actually tests).
    float blocked(uint32_t n) const {
        const uint32_t b = params_.leaf_block_size;
        return float((n + b - 1) / b * b);
    }

    /// fallback_split: object median on the widest centroid axis (used when SAH
    /// finds no split of a too-large range, and below kBvhMedianSplitDepth).
    uint32_t median_split(uint32_t begin, uint32_t end, const Bounds3& centroids) {
        const uint32_t mid = begin + (end - begin) / 2;
        const int axis = max_dimension(centroids.extent());
        std::nth_element(out_.prim_indices.begin() + begin, out_.prim_indices.begin() + mid,
                         out_.prim_indices.begin() + end, [&](uint32_t a, uint32_t b) {
                             const float ca = in_.centers[a][axis], cb = in_.centers[b][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        return mid;
    }

    const BvhBuildInput& in_;
    BvhBuildParams params_;
    Bvh& out_;
    std::atomic<uint32_t> node_count_{0};
};

}  // namespace

Bvh build_bvh(const BvhBuildInput& input, BvhBuilder builder, const BvhBuildParams& params) {
    BvhBuildParams p = params;
    p.bin_count = std::clamp(p.bin_count, 2u, 64u);
    p.max_leaf_size = std::max(p.max_leaf_size, 1u);
    p.leaf_block_size = std::max(p.leaf_block_size, 1u);
    p.sweep_max_prims = std::min(p.sweep_max_prims, binned::kSweepMaxPrims);
    Bvh bvh;
    if (builder == BvhBuilder::binned) {
        build_binned_bvh(input, p, bvh);
        return bvh;
    }
    if (builder == BvhBuilder::automatic) builder = choose_bvh_builder({});
    if (builder == BvhBuilder::sbvh) {
        build_sbvh(input, p, bvh);
        return bvh;
    }
    if (builder == BvhBuilder::sweep) {
        BvhBuildJob(input, p, bvh).run();
        return bvh;
    }
    // Reinsertion starts from one primitive per leaf, so that it may regroup every primitive.
    BvhBuildParams single = p;
    single.max_leaf_size = 1;
    build_binned_bvh(input, single, bvh);
    return reinsert_optimize_bvh(bvh, input.boxes, p);
}

/// Below this many primitives the automatic choice stays binned: a few large
/// primitives make largest_share high, but a tree that small traces no faster rebuilt.
constexpr size_t kAutoMinPrimitives = 1000;

bool looks_like_interior(size_t primitives, double largest_share) {
    return primitives >= kAutoMinPrimitives && largest_share >= kAutoMinLargestShare;
}

BvhBuilder choose_bvh_builder(const BvhWorkload& w) {
    const bool long_render = w.expected_rays >= kAutoMinRaysPerPrimitive * double(w.primitives);
    const bool uneven = looks_like_interior(w.primitives, w.largest_share);
    return long_render && uneven ? BvhBuilder::reinsert : BvhBuilder::binned;
}

double largest_box_area_share(std::span<const Bounds3> boxes, double threshold) {
    const auto n = uint32_t(boxes.size());
    const size_t k = std::max<size_t>(1, boxes.size() / 100);
    // Sums per fixed chunk (build::for_chunks), added in chunk order: the same share at any
    // thread count. The chunks are tasks of the build's team when it calls this from inside
    // one (Accelerator::build), else of a region of their own.
    const bool parallel = n > build::kParallelScanThreshold;
    double totals[build::kScanChunks] = {};
    auto sum = [&totals] {
        double total = 0;
        for (const double t : totals) total += t;
        return total;
    };
    if (threshold > 0.0) {
        // The selection below is serial (most of this function's time at two threads); a
        // pass without it settles most meshes, whose largest box is far from the threshold.
        float largest[build::kScanChunks] = {};
        build::with_build_team(
            [&] {
                build::for_chunks(0, n, [&](uint32_t c, uint32_t b, uint32_t e) {
                    double t = 0;
                    float l = 0.0f;
                    for (uint32_t i = b; i < e; ++i) {
                        const float a = boxes[i].surface_area();
                        t += double(a);
                        l = std::max(l, a);
                    }
                    totals[c] = t;
                    largest[c] = l;
                });
            },
            parallel);
        const double total = sum();
        if (!(total > 0)) return 0.0;
        const float most = *std::max_element(std::begin(largest), std::end(largest));
        // The margin covers the rounding of the summed areas (far below 1e-9 of the total).
        const double bound = double(k) * double(most) * (1.0 + 1e-9) / total;
        if (bound < threshold) return bound;
    }
    // Areas are floats already; keeping them as floats halves the selection's memory. The
    // array is not zero-filled first: that was a serial pass (and its page faults) on one thread.
    const BuildArray<float> areas(boxes.size());
    build::with_build_team(
        [&] {
            build::for_chunks(0, n, [&](uint32_t c, uint32_t b, uint32_t e) {
                double t = 0;
                for (uint32_t i = b; i < e; ++i) t += double(areas[i] = boxes[i].surface_area());
                totals[c] = t;
            });
        },
        parallel);
    const double total = sum();
    if (!(total > 0)) return 0.0;
    float* const a = areas.get();
    std::nth_element(a, a + std::ptrdiff_t(k - 1), a + boxes.size(), std::greater<>());
    double top = 0;
    for (size_t i = 0; i < k; ++i) top += double(areas[i]);
    return top / total;
}

bool parse_bvh_builder(std::string_view text, BvhBuilder& out) {
    if (text == "binned")
        out = BvhBuilder::binned;
    else if (text == "sweep")
        out = BvhBuilder::sweep;
    else if (text == "reinsert")
        out = BvhBuilder::reinsert;
    else if (text == "sbvh")
        out = BvhBuilder::sbvh;
    else if (text == "auto")
        out = BvhBuilder::automatic;
    else
        return false;
    return true;
}

const char* bvh_builder_name(BvhBuilder builder) {
    switch (builder) {
        case BvhBuilder::binned:
            return "binned";
        case BvhBuilder::sweep:
            return "sweep";
        case BvhBuilder::reinsert:
            return "reinsert";
        case BvhBuilder::sbvh:
            return "sbvh";
        case BvhBuilder::automatic:
            return "auto";
    }
    return "binned";
}

}  // namespace sahara
