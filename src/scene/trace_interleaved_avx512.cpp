// Closest-hit rays of a batch traced K at a time on one thread, interleaved (see
// Accelerator::intersect(std::span<Ray>, std::span<Hit>)).
#include <utility>

#include "scene/leaf_blocks.inl"

namespace sahara {

namespace {

/// What a ray of an interleaved batch keeps besides its traversal position (cur, top and
/// tmax_far, which stay in the caller's registers): the box and triangle constants, the
/// best hit so far and the stack of traverse_wide's closest-hit form without node pairing.
struct alignas(32) InterleavedLane {
    Bvh8RayAvx rw;
    TriangleRay tr;
    Hit best;
    float tmin, tmax;
    bool found;
    uint32_t index;  ///< of the ray in the batch
    WideStackEntry stack[(8 - 1) * kBvhMaxDepth + 8];
};

}  // namespace

template <int K>
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) void Accelerator::trace_interleaved_avx512(
    std::span<Ray> rays, std::span<Hit> hits) const {
    const char* const nodes = reinterpret_cast<const char*>(wide8_.nodes.data());
    InterleavedLane lanes[K];
    // A lane's position (what traverse_wide keeps in registers) and the result of its last
    // test: locals of the loop below, handed to the steps by reference, never captured,
    // so that GCC can keep them in registers.
    struct Position {
        WideStackEntry cur;
        float tmax_far;
        int top;
    };
    struct Step {
        Bvh8HitChildren node;
        LeafResult leaf;
        bool paired;
    };
    alignas(32) uint32_t ref[K][8];
    alignas(32) float t[K][8];
    size_t next = 0;
    // Starts the next ray of the batch in lane k; rays that pair nodes are traced alone.
    auto start = [&](int k, Position& p) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        while (next < rays.size()) {
            const size_t i = next++;
            Ray& ray = rays[i];
            hits[i] = Hit{};
            if (pair_rays_ != PairRays::none &&
                (pair_rays_ == PairRays::all || bounds_.contains(ray.origin))) {
                intersect(ray, hits[i]);
                continue;
            }
            const BvhRay br(ray);
            lane.rw = Bvh8RayAvx(br);
            lane.tr = TriangleRay::scattered(ray, br.inv_dir);
            lane.best = Hit{};
            lane.tmin = br.tmin;
            lane.tmax = br.tmax;
            lane.found = false;
            lane.index = uint32_t(i);
            p = Position{WideStackEntry{0, br.tmin}, br.tmax * kRobustFarScale, 0};
            return true;
        }
        return false;
    };
    // Pops lane k's nearest pending entry that can still hold a closer hit; false when
    // none is left.
    auto pop = [&](int k, Position& p) __attribute__((always_inline)) {
        for (;;) {
            if (p.top == 0) return false;
            p.cur = lanes[k].stack[--p.top];
            if (p.cur.t <= p.tmax_far) return true;
        }
    };
    // A round takes one step of every live lane, a node test or a leaf test, in the order
    // traverse_wide takes them, so that each ray's hit is intersect()'s bit for bit. The
    // round makes every lane's test before it branches on any result: a mispredicted
    // branch on one lane's result then does not throw away the other lanes' tests.
    auto test = [&](int k, const Position& p, Step& s) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (const uint32_t count = ref_count(p.cur.ref)) {
            uint32_t next_ref = 0;
            if (p.top > 0 && lane.stack[p.top - 1].t <= p.tmax_far) next_ref = lane.stack[p.top - 1].ref;
            s.paired = false;
            s.leaf = test_blocks_fast<false, false, true>(rays[lane.index], lane.tr, ref_first(p.cur.ref),
                                                          count, ref_first(next_ref), ref_count(next_ref),
                                                          s.paired, lane.tmax, lane.best);
            return;
        }
        const auto& n = *reinterpret_cast<const Bvh8Node*>(nodes + p.cur.ref);
        s.node = intersect_bvh8_compress_avx512(n, lane.rw, lane.tmin, p.tmax_far, ref[k], t[k]);
    };
    // Acts on lane k's test: the next entry to visit, or false when the ray is done.
    auto advance = [&](int k, Position& p, const Step& s) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (const uint32_t count = ref_count(p.cur.ref)) {
            LeafResult r = s.leaf;
            if (r == LeafResult::slow)
                r = test_blocks<false, false, true>(rays[lane.index], lane.tr, ref_first(p.cur.ref), count,
                                                    lane.tmax, lane.best)
                        ? LeafResult::hit
                        : LeafResult::miss;
            if (s.paired) --p.top;
            if (r == LeafResult::hit) {
                lane.found = true;
                p.tmax_far = lane.tmax * kRobustFarScale;
            }
            return pop(k, p);
        }
        if (!s.node.mask) return pop(k, p);
        p.cur = WideStackEntry{s.node.ref0, s.node.t0};
        if (!(s.node.mask & (s.node.mask - 1))) return true;
        const int hit_count = __builtin_popcount(s.node.mask);
        const int base = p.top;
        for (int i = 1; i < hit_count; ++i) {
            WideStackEntry in{ref[k][i], t[k][i]};
            nearer_first_entry(p.cur, in);
            push_sorted_entry(lane.stack, p.top, base, in);
        }
        return true;
    };
    auto retire = [&](int k) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (lane.found) {
            hits[lane.index] = lane.best;
            rays[lane.index].tmax = lane.best.t;
        }
    };
    // Every lane busy while the batch lasts; then the last rays finish one by one. The
    // lanes are spelled out (folds over constant indices, never a loop over k), so that
    // their positions can stay in registers.
    [&]<int... kk>(std::integer_sequence<int, kk...>) __attribute__((always_inline)) {
        Position p[K];
        Step s[K];
        bool live[K];
        bool all = ((live[kk] = start(kk, p[kk])) & ...);
        while (all) {
            (test(kk, p[kk], s[kk]), ...);
            ((advance(kk, p[kk], s[kk]) || (retire(kk), start(kk, p[kk])) || (live[kk] = all = false)), ...);
        }
        (
            [&] {
                if (!live[kk]) return;
                do test(kk, p[kk], s[kk]);
                while (advance(kk, p[kk], s[kk]));
                retire(kk);
            }(),
            ...);
    }
    (std::make_integer_sequence<int, K>{});
}

template void Accelerator::trace_interleaved_avx512<1>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<2>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<3>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<4>(std::span<Ray>, std::span<Hit>) const;

}  // namespace sahara
