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
    WideStackEntry cur[K];
    float tmax_far[K];
    int top[K];
    bool live[K];
    size_t next = 0;
    // Starts the next ray of the batch in lane k; rays that pair nodes are traced alone.
    auto start = [&](int k) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        while (next < rays.size()) {
            const size_t i = next++;
            Ray& ray = rays[i];
            hits[i] = Hit{};
            if (pair_rays_ != PairRays::none && (pair_rays_ == PairRays::all || bounds_.contains(ray.origin))) {
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
            cur[k] = WideStackEntry{0, br.tmin};
            tmax_far[k] = br.tmax * kRobustFarScale;
            top[k] = 0;
            return true;
        }
        return false;
    };
    // Pops lane k's nearest pending entry that can still hold a closer hit; false when
    // none is left.
    auto pop = [&](int k) __attribute__((always_inline)) {
        for (;;) {
            if (top[k] == 0) return false;
            cur[k] = lanes[k].stack[--top[k]];
            if (cur[k].t <= tmax_far[k]) return true;
        }
    };
    // A round takes one step of every live lane, a node test or a leaf test, in the order
    // traverse_wide takes them, so that each ray's hit is intersect()'s bit for bit. The
    // round makes every lane's test before it branches on any result: a mispredicted
    // branch on one lane's result then does not throw away the other lanes' tests.
    alignas(32) uint32_t ref[K][8];
    alignas(32) float t[K][8];
    Bvh8HitChildren h[K];
    LeafResult leaf[K];
    bool paired[K];
    auto test = [&](int k) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (const uint32_t count = ref_count(cur[k].ref)) {
            uint32_t next_ref = 0;
            if (top[k] > 0 && lane.stack[top[k] - 1].t <= tmax_far[k]) next_ref = lane.stack[top[k] - 1].ref;
            paired[k] = false;
            leaf[k] = test_blocks_fast<false, false, true>(rays[lane.index], lane.tr, ref_first(cur[k].ref), count,
                                                           ref_first(next_ref), ref_count(next_ref), paired[k],
                                                           lane.tmax, lane.best);
            return;
        }
        const auto& n = *reinterpret_cast<const Bvh8Node*>(nodes + cur[k].ref);
        h[k] = intersect_bvh8_compress_avx512(n, lane.rw, lane.tmin, tmax_far[k], ref[k], t[k]);
    };
    // Acts on lane k's test: the next entry to visit, or false when the ray is done.
    auto advance = [&](int k) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (const uint32_t count = ref_count(cur[k].ref)) {
            LeafResult r = leaf[k];
            if (r == LeafResult::slow)
                r = test_blocks<false, false, true>(rays[lane.index], lane.tr, ref_first(cur[k].ref), count,
                                                    lane.tmax, lane.best)
                        ? LeafResult::hit
                        : LeafResult::miss;
            if (paired[k]) --top[k];
            if (r == LeafResult::hit) {
                lane.found = true;
                tmax_far[k] = lane.tmax * kRobustFarScale;
            }
            return pop(k);
        }
        if (!h[k].mask) return pop(k);
        cur[k] = WideStackEntry{h[k].ref0, h[k].t0};
        if (!(h[k].mask & (h[k].mask - 1))) return true;
        const int hit_count = __builtin_popcount(h[k].mask);
        const int base = top[k];
        for (int i = 1; i < hit_count; ++i) {
            WideStackEntry in{ref[k][i], t[k][i]};
            nearer_first_entry(cur[k], in);
            push_sorted_entry(lane.stack, top[k], base, in);
        }
        return true;
    };
    for (int k = 0; k < K; ++k) live[k] = start(k);
    // Every lane busy while the batch lasts; then the last rays finish one by one. The
    // lanes are spelled out (a fold over constant indices), so that their positions can
    // stay in registers.
    bool all = true;
    for (int k = 0; k < K; ++k) all = all && live[k];
    auto retire = [&](int k) __attribute__((always_inline)) {
        InterleavedLane& lane = lanes[k];
        if (lane.found) {
            hits[lane.index] = lane.best;
            rays[lane.index].tmax = lane.best.t;
        }
    };
    auto round = [&]<int... kk>(std::integer_sequence<int, kk...>) __attribute__((always_inline)) {
        (test(kk), ...);
        ((advance(kk) || (retire(kk), start(kk)) || (live[kk] = all = false)), ...);
    };
    while (all) round(std::make_integer_sequence<int, K>{});
    for (int k = 0; k < K; ++k) {
        if (!live[k]) continue;
        do test(k);
        while (advance(k));
        retire(k);
    }
}

template void Accelerator::trace_interleaved_avx512<1>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<2>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<3>(std::span<Ray>, std::span<Hit>) const;
template void Accelerator::trace_interleaved_avx512<4>(std::span<Ray>, std::span<Hit>) const;

}  // namespace sahara
