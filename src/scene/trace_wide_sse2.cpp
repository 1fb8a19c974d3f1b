// The wide8 traversal compiled for the baseline (SSE2) target (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

// The SSE2 path never pairs nodes (kPairNodes is always false here).
template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
bool Accelerator::trace_wide_sse2(Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, false, false, false>(ray, hit, counters);
}

template <class Form>
struct TraceWideEntry<SimdPath::sse2, Form> {
    static constexpr auto ptr = &Accelerator::trace_wide_sse2<Form::kAnyHit, Form::kCutouts, Form::kPairNodes,
                                                              typename Form::Counters>;
};

// Every form trace_layout calls on this path.
[[gnu::used]] constexpr auto kTraceWideSse2Forms =
    trace_form_table<SimdPath::sse2>(std::make_integer_sequence<unsigned, kUnpairedTraceForms>{});

}  // namespace sahara
