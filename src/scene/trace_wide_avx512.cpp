// The wide8 traversal compiled for AVX-512 (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) bool Accelerator::trace_wide_avx512(
    Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, true, true, kPairNodes>(ray, hit, counters);
}

template <bool kPairNodes>
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) bool Accelerator::trace_frontier_avx512(
    Ray& ray, Hit& hit, const uint64_t* frontier, int count) const {
    NoTraversalCounters none;
    return trace_wide_body<false, false, true, true, kPairNodes, kStreamFrontierCap>(ray, hit, none, frontier,
                                                                                     count);
}
template bool Accelerator::trace_frontier_avx512<false>(Ray&, Hit&, const uint64_t*, int) const;
template bool Accelerator::trace_frontier_avx512<true>(Ray&, Hit&, const uint64_t*, int) const;

template <class Form>
struct TraceWideEntry<SimdPath::avx512, Form> {
    static constexpr auto ptr = &Accelerator::trace_wide_avx512<Form::kAnyHit, Form::kCutouts,
                                                                Form::kPairNodes, typename Form::Counters>;
};

// Every form trace_layout calls on this path.
[[gnu::used]] constexpr auto kTraceWideAvx512Forms =
    trace_form_table<SimdPath::avx512>(std::make_integer_sequence<unsigned, kTraceForms>{});

}  // namespace sahara
