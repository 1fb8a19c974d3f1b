#pragma once
/// Chunked scans of a primitive range for the top-down builders (bvh_build.cpp,
/// bvh_binned.cpp). Near the root there are fewer subtree tasks than threads, so
/// long ranges are scanned (bounds, bins, partition counts) as a fixed number of
/// OpenMP tasks. The chunks do not depend on the thread count and the builders
/// merge their results exactly, so the tree does not depend on it either.
#include <cstdint>

namespace sahara::build {

/// Ranges longer than this are scanned as kScanChunks tasks.
inline constexpr uint32_t kParallelScanThreshold = 1u << 15;
inline constexpr uint32_t kScanChunks = 8;

/// Start of chunk c (and end of chunk c - 1) of the n-element range starting at `begin`.
inline uint32_t chunk_begin(uint32_t begin, uint32_t n, uint32_t c) {
    return begin + uint32_t(uint64_t(n) * c / kScanChunks);
}

/// Calls fn(chunk, chunk_begin, chunk_end) over [begin, end): inline for short ranges,
/// else as kScanChunks tasks (the caller is inside the build's parallel region).
template <class Fn>
void for_chunks(uint32_t begin, uint32_t end, const Fn& fn) {
    const uint32_t n = end - begin;
    if (n <= kParallelScanThreshold) {
        fn(0u, begin, end);
        return;
    }
    for (uint32_t c = 0; c < kScanChunks; ++c) {
        const uint32_t b = chunk_begin(begin, n, c), e = chunk_begin(begin, n, c + 1);
#pragma omp task default(shared) firstprivate(c, b, e)
        fn(c, b, e);
    }
#pragma omp taskwait
}

}  // namespace sahara::build
