/// Binned SAH builder (Wald, "On fast Construction of SAH-based Bounding Volume
/// Hierarchies", 2007). Every node bins the centroids of its range on all three
/// axes in one pass and partitions in a second one; its children's boxes come
/// from the bins and their centroid bounds from the partition, so there is no
/// separate bounds pass. Primitives are 48-byte records (box, id, centroid)
/// moved in place, read sequentially. Ranges of up to params.sweep_max_prims
/// are split by an exact SAH sweep instead (bvh_small_sweep.h).
///
/// Parallelism: ranges above kParallelScanThreshold are binned and partitioned
/// as kScanChunks OpenMP tasks (stable partition into the other of two buffers), the
/// subtrees above params.parallel_threshold are tasks. The chunks do not depend
/// on the thread count, and every node owns a fixed region of the node array
/// (compacted at the end, in chunks, in the same parallel region), so the tree is the
/// same for any thread count.
#include "accel/bvh_binned.h"
#include "accel/bvh_bins.h"
#include "accel/bvh_small_sweep.h"
#include "accel/build_chunks.h"
#include "accel/build_team.h"

#include <algorithm>
#include <memory>
#include <vector>

namespace sahara {

namespace {

using binned::BinMap;
using binned::Bins;
using binned::Box4;
using binned::fill_bins;
using binned::kMaxBins;
using binned::load_lo;
using binned::PrimRef;
using Split = binned::BinSplit;
using build::chunk_begin;
using build::for_chunks;
using build::kParallelScanThreshold;
using build::kScanChunks;

/// A node's work item: its primitives, box and centroid bounds, and the buffer that
/// holds the primitives (a parallel partition moves them to the other buffer).
struct Range {
    uint32_t begin = 0, end = 0;
    Bounds3 box, centroids;
    PrimRef* refs = nullptr;
};

class BinnedBuild {
   public:
    BinnedBuild(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out)
        : in_(input), params_(params), out_(out), n_(uint32_t(input.boxes.size())) {}

    void run() {
        out_.nodes.clear();
        out_.prim_indices.assign(n_, 0);
        if (n_ == 0) return;
        refs_ = BuildArray<PrimRef>(n_);
        nodes_ = BuildArray<BvhNode>(2 * size_t(n_));
        used_pairs_.assign(n_, 0);
        if (n_ > kParallelScanThreshold) scratch_ = BuildArray<PrimRef>(n_);
        // A taskgroup waits for the subtrees: the compaction runs on all threads.
        build::with_build_team([&] {
#pragma omp taskgroup
            {
                const Range root = init_refs();
                build(0, Bvh::kFirstPair, root, 0);
            }
            // Free before compact() allocates the tree (see HugeBlockReuse).
            refs_ = {};
            scratch_ = {};
            compact();
        });
    }

   private:
    Range init_refs() {
        Box4 boxes[kScanChunks], cents[kScanChunks];
        for_chunks(0, n_, [&](uint32_t c, uint32_t b, uint32_t e) {
            for (uint32_t i = b; i < e; ++i) {
                const Bounds3& box = in_.boxes[i];
                const Vec3& ct = in_.centers[i];
                PrimRef& r = refs_[i];
                r = PrimRef{{box.lo.x, box.lo.y, box.lo.z},
                            i,
                            {box.hi.x, box.hi.y, box.hi.z},
                            0.0f,
                            {ct.x, ct.y, ct.z},
                            0.0f};
                boxes[c].extend(load_lo(r), _mm_load_ps(r.hi));
                cents[c].extend(_mm_load_ps(r.c));
            }
        });
        Box4 box, cent;
        for (uint32_t c = 0; c < kScanChunks; ++c) box.extend(boxes[c]), cent.extend(cents[c]);
        return Range{0, n_, box.bounds(), cent.bounds(), refs_.get()};
    }

    /// Builds the subtree of `r` at node `slot`; its descendants go to the 2 * n - 2 slots from `region`.
    void build(uint32_t slot, uint32_t region, const Range& r, int depth) {
        BvhNode& node = nodes_[slot];
        node.set_box(r.box);
        const uint32_t n = r.end - r.begin;
        Range left, right;
        if (n == 1 || !split(r, depth, left, right)) {
            node.index = r.begin;
            node.count = n;
            for (uint32_t i = r.begin; i < r.end; ++i) out_.prim_indices[i] = r.refs[i].id;
            return;
        }
        used_pairs_[region / 2] = 1;
        node.index = region;
        node.count = 0;
        const uint32_t right_region = region + 2 * (left.end - left.begin);
        if (n > params_.parallel_threshold) {
            // No taskwait: nothing here needs the subtree, and libgomp's taskwait blocks
            // the thread until that very child ends (it runs no other queued subtree), which
            // would leave threads idle. The taskgroup's end waits for every task.
#pragma omp task default(shared) firstprivate(region, left, depth)
            build(region, region + 2, left, depth + 1);
            build(region + 1, right_region, right, depth + 1);
        } else {
            build(region, region + 2, left, depth + 1);
            build(region + 1, right_region, right, depth + 1);
        }
    }

    /// SAH split of `r` into `left` and `right` (partitioned in place), or false for a leaf.
    bool split(const Range& r, int depth, Range& left, Range& right) {
        const uint32_t n = r.end - r.begin;
        const bool may_be_leaf = n <= params_.max_leaf_size;
        if (depth >= kBvhMedianSplitDepth) return !may_be_leaf && median_split(r, left, right);
        if (may_be_leaf && params_.intersection_cost > 0.0f && leaf_is_certain(r)) return false;
        if (n <= params_.sweep_max_prims) return sweep_split(r, may_be_leaf, left, right);
        const uint32_t bins = binned_bin_count(n, params_.bin_count);
        const BinMap map(r.centroids, bins);
        Split best;
        if (n <= kParallelScanThreshold) {
            thread_local Bins all;  // not used across a task scheduling point
            if (n < bins) {
                fill_few_bins(r.refs, r.begin, r.end, map, all);
            } else {
                fill_bins(r.refs, r.begin, r.end, map, all);
            }
            best = find_split(all, map);
            if (best.axis < 0) return !may_be_leaf && median_split(r, left, right);
            if (may_be_leaf && is_leaf_cheaper(r, n, best)) return false;
            partition_serial(r, map, best, left, right);
        } else {
            std::vector<Bins> parts(kScanChunks);
            for_chunks(r.begin, r.end,
                       [&](uint32_t c, uint32_t b, uint32_t e) { fill_bins(r.refs, b, e, map, parts[c]); });
            auto all = std::make_unique<Bins>();
            all->clear(bins);
            for (const Bins& p : parts) all->add(p, bins);
            best = find_split(*all, map);
            if (best.axis < 0) return !may_be_leaf && median_split(r, left, right);
            if (may_be_leaf && is_leaf_cheaper(r, n, best)) return false;
            partition_parallel(r, map, best, parts, left, right);
        }
        left.box = best.left;
        right.box = best.right;
        return true;
    }

    /// split() of a short range by the exact SAH sweep (bvh_small_sweep.h).
    bool sweep_split(const Range& r, bool may_be_leaf, Range& left, Range& right) {
        PrimRef* refs = &r.refs[r.begin];
        const uint32_t n = r.end - r.begin;
        const binned::SmallSweep sweep(refs, n);
        const binned::SweepSplit s = sweep.best({params_.intersection_cost, params_.leaf_block_size});
        if (s.axis < 0) return !may_be_leaf && median_split(r, left, right);
        Split bound;
        bound.cost = s.cost;
        if (may_be_leaf && is_leaf_cheaper(r, n, bound)) return false;
        Box4 lbox, rbox, lcent, rcent;
        sweep.apply(refs, s, lbox, rbox, lcent, rcent);
        const uint32_t mid = r.begin + s.left_count;
        left = Range{r.begin, mid, lbox.bounds(), lcent.bounds(), r.refs};
        right = Range{mid, r.end, rbox.bounds(), rcent.bounds(), r.refs};
        return true;
    }

    /// Whether is_leaf_cheaper holds for every split of `r`, so binning can be skipped. Each
    /// side of a split holds a primitive, so its area is at least that primitive's (the areas
    /// round monotonically), and blocked() of a side is at least blocked(1): every split costs
    /// at least intersection_cost * (a_max + a_min) * blocked(1), computed here in the same
    /// order, from the largest and smallest primitive box areas.
    bool leaf_is_certain(const Range& r) const {
        float a_max = 0.0f, a_min = kInfinity;
        for (uint32_t i = r.begin; i < r.end; ++i) {
            Box4 b;
            b.extend(load_lo(r.refs[i]), _mm_load_ps(r.refs[i].hi));
            const float a = b.area();
            if (!(a >= 0.0f)) return false;  // a NaN box: no bound, bin as usual
            a_max = std::max(a_max, a);
            a_min = std::min(a_min, a);
        }
        const float one = blocked(1);
        const float lowest_split_cost = params_.intersection_cost * (a_max * one + a_min * one);
        Split bound;
        bound.cost = lowest_split_cost;
        return is_leaf_cheaper(r, r.end - r.begin, bound);
    }

    bool is_leaf_cheaper(const Range& r, uint32_t n, const Split& s) const {
        const float area = r.box.surface_area();
        return params_.intersection_cost * blocked(n) * area <= params_.traversal_cost * area + s.cost;
    }

    /// fill_bins for fewer primitives than bins: clears all counts but only the boxes of
    /// the bins they fall in (find_split reads no other box); near the leaves the full
    /// clear cost more than the binning.
    static void fill_few_bins(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map,
                              Bins& out) {
        out.clear_counts(uint32_t(map.last) + 1);
        const __m128i last = _mm_set1_epi32(map.last);
        alignas(16) uint32_t k[kMaxBins][4];
        for (uint32_t i = begin; i < end; ++i) {
            _mm_store_si128(reinterpret_cast<__m128i*>(k[i - begin]), map.bins(_mm_load_ps(refs[i].c), last));
            for (int a = 0; a < 3; ++a) out.box[a][k[i - begin][a]] = Box4{};
        }
        for (uint32_t i = begin; i < end; ++i) {
            const __m128 lo = load_lo(refs[i]), hi = _mm_load_ps(refs[i].hi);
            for (int a = 0; a < 3; ++a) {
                out.box[a][k[i - begin][a]].extend(lo, hi);
                ++out.count[a][k[i - begin][a]];
            }
        }
    }

    Split find_split(const Bins& bins, const BinMap& map) const {
        return binned::find_bin_split(bins, map, {params_.intersection_cost, params_.leaf_block_size});
    }

    /// In-place partition of a short range; accumulates the children's centroid bounds.
    void partition_serial(const Range& r, const BinMap& map, const Split& s, Range& left, Range& right) {
        PrimRef* lo = &r.refs[r.begin];
        PrimRef* hi = &r.refs[r.end];
        Box4 lc, rc;
        const binned::SideTest side(map, s.axis, s.pos, r.centroids.hi[s.axis], r.end - r.begin);
        for (;;) {
            while (lo < hi && side.left(*lo)) lc.extend(_mm_load_ps(lo->c)), ++lo;
            while (lo < hi && !side.left(hi[-1])) --hi, rc.extend(_mm_load_ps(hi->c));
            if (lo >= hi) break;
            std::swap(*lo, hi[-1]);
            lc.extend(_mm_load_ps(lo->c));
            ++lo;
            --hi;
            rc.extend(_mm_load_ps(hi->c));
        }
        const auto mid = uint32_t(lo - r.refs);
        left.begin = r.begin;
        left.end = right.begin = mid;
        right.end = r.end;
        left.centroids = lc.bounds();
        right.centroids = rc.bounds();
        left.refs = right.refs = r.refs;
    }

    /// Stable partition of a long range through scratch_, chunk by chunk: each chunk's
    /// left and right counts come from its bins, so every chunk knows where to write.
    void partition_parallel(const Range& r, const BinMap& map, const Split& s, const std::vector<Bins>& parts,
                            Range& left, Range& right) {
        uint32_t left_at[kScanChunks], right_at[kScanChunks];
        uint32_t lsum = r.begin, rsum = r.begin + s.left_count;
        const uint32_t n = r.end - r.begin;
        for (uint32_t c = 0; c < kScanChunks; ++c) {
            uint32_t lcount = 0;
            for (uint32_t b = 0; b < s.pos; ++b) lcount += parts[c].count[s.axis][b];
            const uint32_t cb = chunk_begin(0, n, c), ce = chunk_begin(0, n, c + 1);
            left_at[c] = lsum;
            right_at[c] = rsum;
            lsum += lcount;
            rsum += (ce - cb) - lcount;
        }
        Box4 lc[kScanChunks], rc[kScanChunks];
        PrimRef* const to = r.refs == refs_.get() ? scratch_.get() : refs_.get();
        const binned::SideTest side(map, s.axis, s.pos, r.centroids.hi[s.axis], r.end - r.begin);
        for_chunks(r.begin, r.end, [&](uint32_t c, uint32_t b, uint32_t e) {
            uint32_t l = left_at[c], h = right_at[c];
            for (uint32_t i = b; i < e; ++i) {
                const PrimRef& p = r.refs[i];
                if (side.left(p)) {
                    to[l++] = p;
                    lc[c].extend(_mm_load_ps(p.c));
                } else {
                    to[h++] = p;
                    rc[c].extend(_mm_load_ps(p.c));
                }
            }
        });
        Box4 lall, rall;
        for (uint32_t c = 0; c < kScanChunks; ++c) lall.extend(lc[c]), rall.extend(rc[c]);
        left.begin = r.begin;
        left.end = right.begin = r.begin + s.left_count;
        right.end = r.end;
        left.centroids = lall.bounds();
        right.centroids = rall.bounds();
        left.refs = right.refs = to;
    }

    /// Object median on the widest centroid axis (below kBvhMedianSplitDepth, or when no
    /// bin boundary separates the centroids); the children's bounds are scanned.
    bool median_split(const Range& r, Range& left, Range& right) {
        const int axis = max_dimension(r.centroids.extent());
        const uint32_t mid = r.begin + (r.end - r.begin) / 2;
        std::nth_element(&r.refs[r.begin], &r.refs[mid], &r.refs[r.end],
                         [axis](const PrimRef& a, const PrimRef& b) {
                             return a.c[axis] < b.c[axis] || (a.c[axis] == b.c[axis] && a.id < b.id);
                         });
        scan(r.refs, r.begin, mid, left);
        scan(r.refs, mid, r.end, right);
        return true;
    }

    static void scan(PrimRef* refs, uint32_t begin, uint32_t end, Range& out) {
        Box4 box, cent;
        for (uint32_t i = begin; i < end; ++i) {
            box.extend(load_lo(refs[i]), _mm_load_ps(refs[i].hi));
            cent.extend(_mm_load_ps(refs[i].c));
        }
        out = Range{begin, end, box.bounds(), cent.bounds(), refs};
    }

    /// Primitive count rounded up to whole leaf blocks (what a leaf of n actually tests).
    /// (No division for the usual power-of-two block sizes: it is evaluated at every bin boundary.)
    float blocked(uint32_t n) const {
        const uint32_t b = params_.leaf_block_size;
        if ((b & (b - 1)) == 0) return float((n + b - 1) & ~(b - 1));
        return float((n + b - 1) / b * b);
    }

    /// Removes the unused pairs of the node regions, keeping the order (depth-first, left
    /// before right: the order of a serial build that allocates pairs as it goes). Runs in
    /// the build's parallel region: the copy is chunked.
    void compact() {
        if (nodes_[0].is_leaf()) {
            out_.nodes.assign(1, nodes_[0]);
            return;
        }
        used_pairs_[0] = 1;
        // The pairs' new numbers: a count per chunk, then each chunk numbers its own from
        // the chunks before it.
        uint32_t first_pair[kScanChunks] = {};
        for_chunks(0, n_, [&](uint32_t c, uint32_t b, uint32_t e) {
            uint32_t used = 0;
            for (uint32_t k = b; k < e; ++k) used += used_pairs_[k];
            first_pair[c] = used;
        });
        uint32_t pairs = 0;
        for (uint32_t& f : first_pair) {
            const uint32_t used = f;
            f = pairs;
            pairs += used;
        }
        const BuildArray<uint32_t> new_pair(n_);  // every entry written below
        for_chunks(0, n_, [&](uint32_t c, uint32_t b, uint32_t e) {
            uint32_t next = first_pair[c];
            for (uint32_t k = b; k < e; ++k) {
                new_pair[k] = next;
                next += used_pairs_[k];
            }
        });
        out_.nodes.resize(2 * size_t(pairs));
        for_chunks(0, n_, [&](uint32_t, uint32_t b, uint32_t e) {
            for (uint32_t k = b; k < e; ++k) {
                if (!used_pairs_[k]) continue;
                for (uint32_t j = 0; j < (k == 0 ? 1u : 2u); ++j) {  // nodes[1], padding, is set below
                    BvhNode node = nodes_[2 * k + j];
                    if (!node.is_leaf()) node.index = 2 * new_pair[node.index / 2];
                    out_.nodes[2 * new_pair[k] + j] = node;
                }
            }
        });
        out_.nodes[1] = BvhNode{{0, 0, 0, 0, 0, 0}, 0, 0};
    }

    const BvhBuildInput& in_;
    const BvhBuildParams params_;
    Bvh& out_;
    const uint32_t n_;
    BuildArray<PrimRef> refs_, scratch_;
    BuildArray<BvhNode> nodes_;
    std::vector<uint8_t> used_pairs_;
};

}  // namespace

void build_binned_bvh(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out) {
    BinnedBuild(input, params, out).run();
}

}  // namespace sahara
