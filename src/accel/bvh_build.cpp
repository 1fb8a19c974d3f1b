/// Top-down SAH builders (MacDonald and Booth, "Heuristics for ray tracing
/// using space subdivision", 1990). The binned builder follows Wald, "On fast
/// Construction of SAH-based Bounding Volume Hierarchies" (2007): centroids are
/// binned per axis and only the bin boundaries are evaluated. The sweep
/// builder evaluates every split of the centroid-sorted primitives on every
/// axis (exact object-split SAH), O(n log^2 n); it exists to measure how much
/// quality binning gives away.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <string_view>
#include <vector>

#include "accel/bvh.h"

namespace sahara {

namespace {

/// The chosen partition of a node's range.
struct Split {
    int axis = -1;           ///< -1: no valid split found
    uint32_t pos = 0;        ///< binned: first bin of the right side; sweep: primitives on the left
    float cost = kInfinity;  ///< unnormalised: traversal * A + intersection * sum(A_child * n_child)
};

/// A centroid bin: bounds and primitive count.
struct Bin {
    Bounds3 box;
    uint32_t count = 0;
};

class BvhBuildJob {
   public:
    BvhBuildJob(const BvhBuildInput& input, BvhBuilder builder, const BvhBuildParams& params, Bvh& out)
        : in_(input), builder_(builder), params_(params), out_(out) {}

    void run() {
        const auto n = uint32_t(in_.boxes.size());
        out_.prim_indices.resize(n);
        for (uint32_t i = 0; i < n; ++i) out_.prim_indices[i] = i;
        if (n == 0) return;
        out_.nodes.resize(2 * size_t(n));  // at most 2n - 1 nodes, plus the padding node
        node_count_ = Bvh::kFirstPair;
#pragma omp parallel
#pragma omp single
        build_node(0, 0, n, 0);
        out_.nodes.resize(out_.nodes[0].is_leaf() ? 1 : node_count_.load());
        if (out_.nodes.size() > 1) out_.nodes[1] = BvhNode{{0, 0, 0, 0, 0, 0}, 0, 0};
    }

   private:
    /// Ranges longer than this are scanned (bounds, bins) as kScanChunks OpenMP tasks: near the
    /// root there are fewer subtree tasks than threads. The chunks do not depend on the thread
    /// count and merging boxes and counts is exact, so the tree does not either.
    static constexpr uint32_t kParallelScanThreshold = 1u << 15;
    static constexpr uint32_t kScanChunks = 8;

    /// Calls fn(chunk, chunk_begin, chunk_end) over [begin, end): inline for short ranges,
    /// else as kScanChunks tasks (the caller is inside the build's parallel region).
    template <class Fn>
    static void for_chunks(uint32_t begin, uint32_t end, const Fn& fn) {
        const uint32_t n = end - begin;
        if (n <= kParallelScanThreshold) {
            fn(0u, begin, end);
            return;
        }
        for (uint32_t c = 0; c < kScanChunks; ++c) {
            const auto b = begin + uint32_t(uint64_t(n) * c / kScanChunks);
            const auto e = begin + uint32_t(uint64_t(n) * (c + 1) / kScanChunks);
#pragma omp task default(shared) firstprivate(c, b, e)
            fn(c, b, e);
        }
#pragma omp taskwait
    }

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
#pragma omp task default(shared) firstprivate(first_child, begin, mid, depth)
            build_node(first_child, begin, mid, depth + 1);
            build_node(first_child + 1, mid, end, depth + 1);
#pragma omp taskwait
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
        const Split split = builder_ == BvhBuilder::binned ? find_binned_split(begin, end, centroids)
                                                           : find_sweep_split(begin, end, centroids);
        if (split.axis < 0) return may_be_leaf ? begin : median_split(begin, end, centroids);
        const float area = box.surface_area();
        const float leaf_cost = params_.intersection_cost * blocked(n) * area;
        const float split_cost = params_.traversal_cost * area + split.cost;
        if (may_be_leaf && leaf_cost <= split_cost) return begin;
        return builder_ == BvhBuilder::binned ? partition_binned(begin, end, centroids, split)
                                              : partition_sweep(begin, end, split);
    }

    // ---- binned SAH ------------------------------------------------------

    uint32_t bin_of(float c, float lo, float scale) const {
        const auto b = int((c - lo) * scale);
        return uint32_t(std::clamp(b, 0, int(params_.bin_count) - 1));
    }

    /// One pass over [begin, end) fills the bins of all three axes (3 x bin_count, cleared by the caller).
    void fill_bins(uint32_t begin, uint32_t end, const float lo[3], const float scale[3], Bin* bins) const {
        for (uint32_t i = begin; i < end; ++i) {
            const uint32_t p = out_.prim_indices[i];
            for (int axis = 0; axis < 3; ++axis) {
                Bin& target = bins[size_t(axis) * params_.bin_count +
                                   bin_of(in_.centers[p][axis], lo[axis], scale[axis])];
                target.box.extend(in_.boxes[p]);
                ++target.count;
            }
        }
    }

    Split find_binned_split(uint32_t begin, uint32_t end, const Bounds3& centroids) const {
        const uint32_t bins = params_.bin_count;
        Split best;
        float right_area[64];
        uint32_t right_count[64];
        float lo[3], scale[3];
        for (int axis = 0; axis < 3; ++axis) {
            const float extent = centroids.hi[axis] - centroids.lo[axis];
            lo[axis] = centroids.lo[axis];
            scale[axis] = extent > 0.0f ? float(bins) / extent : 0.0f;
        }
        // Only 3 * bins entries are cleared (a fixed 3 x 64 array would be cleared whole at every
        // node). Not used across for_chunks' taskwait, where this thread may run another node.
        thread_local std::vector<Bin> all_bins;
        const size_t per_chunk = 3 * size_t(bins);
        if (end - begin <= kParallelScanThreshold) {
            all_bins.assign(per_chunk, Bin{});
            fill_bins(begin, end, lo, scale, all_bins.data());
        } else {
            std::vector<Bin> parts(kScanChunks * per_chunk);
            for_chunks(begin, end, [&](uint32_t c, uint32_t b, uint32_t e) {
                fill_bins(b, e, lo, scale, &parts[c * per_chunk]);
            });
            all_bins.assign(per_chunk, Bin{});
            for (uint32_t c = 0; c < kScanChunks; ++c)
                for (size_t k = 0; k < per_chunk; ++k) {
                    all_bins[k].box.extend(parts[c * per_chunk + k].box);
                    all_bins[k].count += parts[c * per_chunk + k].count;
                }
        }
        for (int axis = 0; axis < 3; ++axis) {
            if (!(scale[axis] > 0.0f)) continue;
            const Bin* bin = &all_bins[size_t(axis) * bins];
            // find_best_split: suffix sweep from the right, then prefix sweep from the left.
            Bounds3 acc;
            uint32_t cnt = 0;
            for (uint32_t b = bins - 1; b > 0; --b) {
                acc.extend(bin[b].box);
                cnt += bin[b].count;
                right_area[b] = acc.surface_area();
                right_count[b] = cnt;
            }
            acc = Bounds3{};
            cnt = 0;
            for (uint32_t b = 1; b < bins; ++b) {
                acc.extend(bin[b - 1].box);
                cnt += bin[b - 1].count;
                if (cnt == 0 || right_count[b] == 0) continue;
                const float cost = sah_cost(acc.surface_area(), cnt, right_area[b], right_count[b]);
                if (cost < best.cost) best = Split{axis, b, cost};
            }
        }
        return best;
    }

    uint32_t partition_binned(uint32_t begin, uint32_t end, const Bounds3& centroids, const Split& split) {
        const float lo = centroids.lo[split.axis];
        const float scale = float(params_.bin_count) / (centroids.hi[split.axis] - lo);
        auto* first = out_.prim_indices.data() + begin;
        auto* mid = std::partition(first, out_.prim_indices.data() + end, [&](uint32_t p) {
            return bin_of(in_.centers[p][split.axis], lo, scale) < split.pos;
        });
        return uint32_t(mid - out_.prim_indices.data());
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
    BvhBuilder builder_;
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
    Bvh bvh;
    if (builder != BvhBuilder::reinsert) {
        BvhBuildJob(input, builder, p, bvh).run();
        return bvh;
    }
    // Reinsertion starts from one primitive per leaf, so that it may regroup every primitive.
    BvhBuildParams single = p;
    single.max_leaf_size = 1;
    BvhBuildJob(input, BvhBuilder::binned, single, bvh).run();
    return reinsert_optimize_bvh(bvh, input.boxes, p);
}

bool parse_bvh_builder(std::string_view text, BvhBuilder& out) {
    if (text == "binned")
        out = BvhBuilder::binned;
    else if (text == "sweep")
        out = BvhBuilder::sweep;
    else if (text == "reinsert")
        out = BvhBuilder::reinsert;
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
    }
    return "binned";
}

}  // namespace sahara
