// The wide-BVH traversal compiled for AVX-512 (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

template <bool kAnyHit, bool kCutouts, bool kBlocks, bool kPairNodes, int N, class Counters>
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) bool Accelerator::trace_wide_avx512(
    const BvhWide<N>& tree, Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, kBlocks, N, true, true, kPairNodes>(tree, ray, hit, counters);
}

// Every form trace_layout calls: the 8-wide tree with and without node pairing, the 4-wide ones with and
// without blocks.
#define SAHARA_INSTANTIATE(kAny, kCut, Ctr)                                                                 \
    template bool Accelerator::trace_wide_avx512<kAny, kCut, true, true, 8, Ctr>(const BvhWide<8>&, Ray&,   \
                                                                                 Hit&, Ctr&) const;         \
    template bool Accelerator::trace_wide_avx512<kAny, kCut, true, false, 8, Ctr>(const BvhWide<8>&, Ray&,  \
                                                                                  Hit&, Ctr&) const;        \
    template bool Accelerator::trace_wide_avx512<kAny, kCut, true, false, 4, Ctr>(const BvhWide<4>&, Ray&,  \
                                                                                  Hit&, Ctr&) const;        \
    template bool Accelerator::trace_wide_avx512<kAny, kCut, false, false, 4, Ctr>(const BvhWide<4>&, Ray&, \
                                                                                   Hit&, Ctr&) const;
SAHARA_FOR_EACH_TRACE_FORM(SAHARA_INSTANTIATE)
#undef SAHARA_INSTANTIATE

}  // namespace sahara
