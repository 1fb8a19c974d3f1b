#include "accel/simd_path.h"

#include <cstdlib>
#include <cstring>

namespace sahara {

bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

bool cpu_has_avx512() {
#if defined(__x86_64__) || defined(__i386__)
    return cpu_has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#else
    return false;
#endif
}

SimdPath best_simd_path() {
    return cpu_has_avx512() ? SimdPath::avx512 : cpu_has_avx2() ? SimdPath::avx2 : SimdPath::sse2;
}

namespace {

/// `want`, or the widest path below it that this CPU runs.
SimdPath supported(SimdPath want) {
    if (want == SimdPath::avx512 && !cpu_has_avx512()) want = SimdPath::avx2;
    if (want == SimdPath::avx2 && !cpu_has_avx2()) want = SimdPath::sse2;
    return want;
}

}  // namespace

std::vector<SimdPath> runnable_simd_paths() {
    std::vector<SimdPath> paths{SimdPath::sse2};
    if (cpu_has_avx2()) paths.push_back(SimdPath::avx2);
    if (cpu_has_avx512()) paths.push_back(SimdPath::avx512);
    return paths;
}

namespace detail {
std::atomic<int> g_simd_path{-1};
}  // namespace detail

SimdPath init_simd_path() {
    static const SimdPath from_env = [] {
        const char* env = std::getenv("SAHARA_SIMD");
        if (env && std::strcmp(env, "sse2") == 0) return SimdPath::sse2;
        if (env && std::strcmp(env, "avx2") == 0) return supported(SimdPath::avx2);
        return best_simd_path();
    }();
    int expected = -1;
    detail::g_simd_path.compare_exchange_strong(expected, int(from_env), std::memory_order_relaxed);
    return SimdPath(detail::g_simd_path.load(std::memory_order_relaxed));
}

void force_simd_path(SimdPath path) {
    detail::g_simd_path.store(int(supported(path)), std::memory_order_relaxed);
}

void clear_forced_simd_path() { detail::g_simd_path.store(-1, std::memory_order_relaxed); }

const char* simd_path_name(SimdPath path) {
    return path == SimdPath::avx512 ? "avx512" : path == SimdPath::avx2 ? "avx2" : "sse2";
}

}  // namespace sahara
