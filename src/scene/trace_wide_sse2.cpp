// The wide-BVH traversal compiled for the baseline (SSE2) target (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

template <bool kAnyHit, bool kCutouts, bool kBlocks, int N, class Counters>
bool Accelerator::trace_wide(const BvhWide<N>& tree, Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, kBlocks, N, false, false, false>(tree, ray, hit, counters);
}

// Every form trace_layout calls: the 8-wide tree and the 4-wide ones with and without blocks.
#define SAHARA_INSTANTIATE(kAny, kCut, Ctr)                                                               \
    template bool Accelerator::trace_wide<kAny, kCut, true, 8, Ctr>(const BvhWide<8>&, Ray&, Hit&, Ctr&)  \
        const;                                                                                            \
    template bool Accelerator::trace_wide<kAny, kCut, true, 4, Ctr>(const BvhWide<4>&, Ray&, Hit&, Ctr&)  \
        const;                                                                                            \
    template bool Accelerator::trace_wide<kAny, kCut, false, 4, Ctr>(const BvhWide<4>&, Ray&, Hit&, Ctr&) \
        const;
SAHARA_FOR_EACH_TRACE_FORM(SAHARA_INSTANTIATE)
#undef SAHARA_INSTANTIATE

}  // namespace sahara
