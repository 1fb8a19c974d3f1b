#pragma once
/// The instruction set the SIMD code runs (SSE2, AVX2, AVX-512): chosen once from
/// the CPU and SAHARA_SIMD (the one reader of it), or forced by tests.
#include <atomic>
#include <cstdint>
#include <vector>

namespace sahara {

/// Which instruction set the traversals run: the single-ray wide8 traversal (one body,
/// three instantiations) and the packet kernels (accel/packet.h) alike.
enum class SimdPath : uint8_t {
    sse2,    ///< baseline of every x86-64 CPU
    avx2,    ///< VEX encoding, 8-wide node tests in one AVX step
    avx512,  ///< the AVX2 code with AVX-512VL (32 vector registers) and its own 8-wide node step
};

namespace detail {
extern std::atomic<int> g_simd_path;  ///< -1 until the first call of active_simd_path()
}  // namespace detail
/// Reads SAHARA_SIMD and the CPU once (behind active_simd_path()); the one reader of
/// SAHARA_SIMD.
SimdPath init_simd_path();
/// The path in use: the widest the CPU has, unless force_simd_path() was called or the
/// environment variable SAHARA_SIMD=sse2|avx2|avx512 asks for a narrower one. SAHARA_SIMD
/// is a testing switch: it runs the fallback paths on a CPU that has wider ones (results
/// are the same on every path). One relaxed load per ray.
inline SimdPath active_simd_path() {
    const int p = detail::g_simd_path.load(std::memory_order_relaxed);
    return p >= 0 ? SimdPath(p) : init_simd_path();
}
/// Forces a path (tests); a path the CPU lacks falls back to the widest it has.
void force_simd_path(SimdPath path);
/// Undoes force_simd_path(): back to the CPU's and SAHARA_SIMD's choice.
void clear_forced_simd_path();
/// Whether this CPU can run the AVX2 path.
bool cpu_has_avx2();
/// Whether this CPU can run the AVX-512 path (F, VL, BW, DQ).
bool cpu_has_avx512();
/// The widest path this CPU runs.
SimdPath best_simd_path();
/// Every path this CPU runs, narrowest first (tests force each).
std::vector<SimdPath> runnable_simd_paths();
/// "sse2", "avx2" or "avx512".
const char* simd_path_name(SimdPath path);

}  // namespace sahara
