// The wide8 traversal compiled for AVX-512 (see trace_wide.inl).
#include "scene/trace_wide.inl"

namespace sahara {

template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) bool Accelerator::trace_wide_avx512(
    Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, true, true, kPairNodes>(ray, hit, counters);
}

template <class Form>
struct TraceWideEntry<SimdPath::avx512, Form> {
    static constexpr auto ptr = &Accelerator::trace_wide_avx512<Form::kAnyHit, Form::kCutouts,
                                                                Form::kPairNodes, typename Form::Counters>;
};

// Every form trace_layout calls on this path.
[[gnu::used]] constexpr auto kTraceWideAvx512Forms =
    trace_form_table<SimdPath::avx512>(std::make_integer_sequence<unsigned, kTraceForms>{});

}  // namespace sahara
