// The wide8 traversal compiled for AVX2 (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
__attribute__((target("avx2"))) bool Accelerator::trace_wide_avx2(Ray& ray, Hit& hit,
                                                                  Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, true, false, kPairNodes>(ray, hit, counters);
}

template <class Form>
struct TraceWideEntry<SimdPath::avx2, Form> {
    static constexpr auto ptr = &Accelerator::trace_wide_avx2<Form::kAnyHit, Form::kCutouts, Form::kPairNodes,
                                                              typename Form::Counters>;
};

// Every form trace_layout calls on this path.
[[gnu::used]] constexpr auto kTraceWideAvx2Forms =
    trace_form_table<SimdPath::avx2>(std::make_integer_sequence<unsigned, kTraceForms>{});

}  // namespace sahara
