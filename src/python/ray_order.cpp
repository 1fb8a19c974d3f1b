#include "python/ray_order.h"

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace sahara::python {

namespace {

constexpr int kBitsPerCoordinate = 5;
constexpr int kCells = 1 << kBitsPerCoordinate;
constexpr int kRadixBits = 10;  ///< three passes over the 30-bit code
constexpr size_t kBuckets = size_t(1) << kRadixBits;

/// The cell of x in [lo, lo + kCells / scale); NaN and everything below go to cell 0.
uint32_t cell(float x, float lo, float scale) {
    const float f = (x - lo) * scale;
    return f >= 0.0f ? (f < float(kCells - 1) ? uint32_t(f) : uint32_t(kCells - 1)) : 0u;
}

/// Bit b of coordinate k goes to bit 6 b + k: nearby codes are nearby in all six.
uint32_t morton6(const uint32_t (&q)[6]) {
    uint32_t code = 0;
    for (int b = 0; b < kBitsPerCoordinate; ++b)
        for (int k = 0; k < 6; ++k) code |= ((q[k] >> b) & 1u) << (6 * b + k);
    return code;
}

struct OriginBounds {
    float lo[3], scale[3];
};

OriginBounds origin_bounds(const RayBatch& rays, int threads) {
    const auto n = int64_t(rays.size());
    float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                   std::numeric_limits<float>::max()};
    float hi[3] = {-lo[0], -lo[1], -lo[2]};
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : lo[:3]) reduction(max : hi[:3])
    for (int64_t i = 0; i < n; ++i) {
        const Vec3 o = rays.ray(size_t(i)).origin;
        for (int k = 0; k < 3; ++k)
            if (std::isfinite(o[k])) lo[k] = std::min(lo[k], o[k]), hi[k] = std::max(hi[k], o[k]);
    }
    OriginBounds b{};
    for (int k = 0; k < 3; ++k) {
        const float extent = hi[k] - lo[k];
        b.lo[k] = lo[k];
        b.scale[k] = extent > 0.0f && std::isfinite(extent) ? float(kCells) / extent : 0.0f;
    }
    return b;
}

/// Morton code (high 32 bits) and batch index (low 32 bits) of every ray.
std::vector<uint64_t> keyed_indices(const RayBatch& rays, int threads) {
    const OriginBounds b = origin_bounds(rays, threads);
    const auto n = int64_t(rays.size());
    std::vector<uint64_t> keys(static_cast<size_t>(n));
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t i = 0; i < n; ++i) {
        const Ray r = rays.ray(size_t(i));
        const float len = std::sqrt(dot(r.dir, r.dir));
        const float inv = len > 0.0f && std::isfinite(len) ? 1.0f / len : 0.0f;
        uint32_t q[6];
        for (int k = 0; k < 3; ++k) {
            q[k] = cell(r.dir[k] * inv, -1.0f, 0.5f * float(kCells));
            q[3 + k] = cell(r.origin[k], b.lo[k], b.scale[k]);
        }
        keys[size_t(i)] = uint64_t(morton6(q)) << 32 | uint64_t(i);
    }
    return keys;
}

/// One stable counting pass of an LSD radix sort on the bits from `shift`: each thread
/// counts and then places one contiguous block of `in`.
void radix_pass(const std::vector<uint64_t>& in, std::vector<uint64_t>& out, int shift, int threads) {
    const size_t n = in.size();
    std::vector<size_t> counts(size_t(threads) * kBuckets);
#pragma omp parallel num_threads(threads)
    {
        const auto t = size_t(omp_get_thread_num()), nt = size_t(omp_get_num_threads());
        const size_t lo = n * t / nt, hi = n * (t + 1) / nt;
        size_t* count = &counts[t * kBuckets];
        for (size_t i = lo; i < hi; ++i) ++count[(in[i] >> shift) & (kBuckets - 1)];
#pragma omp barrier
#pragma omp single
        {
            size_t next = 0;  // bucket by bucket, thread by thread: keeps the pass stable
            for (size_t bucket = 0; bucket < kBuckets; ++bucket)
                for (size_t u = 0; u < nt; ++u) {
                    const size_t c = counts[u * kBuckets + bucket];
                    counts[u * kBuckets + bucket] = next;
                    next += c;
                }
        }
        for (size_t i = lo; i < hi; ++i) out[count[(in[i] >> shift) & (kBuckets - 1)]++] = in[i];
    }
}

}  // namespace

std::vector<uint32_t> ray_order(const RayBatch& rays, int threads) {
    const size_t n = rays.size();
    if (n < kMinSortedRays || n > size_t(std::numeric_limits<uint32_t>::max())) return {};
    if (threads <= 0) threads = omp_get_max_threads();
    std::vector<uint64_t> keys = keyed_indices(rays, threads);
    std::vector<uint64_t> scratch(n);
    for (int shift = 32; shift < 32 + 6 * kBitsPerCoordinate; shift += kRadixBits) {
        radix_pass(keys, scratch, shift, threads);
        keys.swap(scratch);
    }
    std::vector<uint32_t> order(n);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t i = 0; i < int64_t(n); ++i) order[size_t(i)] = uint32_t(keys[size_t(i)]);
    return order;
}

std::vector<Ray> gather_rays(const RayBatch& rays, const std::vector<uint32_t>& order, int threads) {
    std::vector<Ray> out(order.size());
    const auto n = int64_t(order.size());
#pragma omp parallel for schedule(static) num_threads(threads > 0 ? threads : omp_get_max_threads())
    for (int64_t k = 0; k < n; ++k) out[size_t(k)] = rays.ray(order[size_t(k)]);
    return out;
}

bool runs_are_coherent(const RayBatch& rays, float max_chord, float max_offset) {
    constexpr size_t kSampledRuns = 64;
    const size_t runs = rays.size() / size_t(kPacketSize);
    if (runs == 0) return false;
    size_t coherent = 0, sampled = 0;
    for (size_t s = 0; s < std::min(runs, kSampledRuns); ++s, ++sampled) {
        const size_t first = s * runs / std::min(runs, kSampledRuns) * size_t(kPacketSize);
        RayPacket packet;
        for (int l = 0; l < kPacketSize; ++l) packet.set(l, rays.ray(first + size_t(l)));
        coherent += packet_is_coherent(packet, max_chord, max_offset);
    }
    return 2 * coherent >= sampled;
}

bool packet_is_coherent(const RayPacket& packet, float max_chord, float max_offset) {
    const auto unit = [&](int i) {
        const Vec3 d(packet.dir[0][i], packet.dir[1][i], packet.dir[2][i]);
        return d / std::sqrt(dot(d, d));
    };
    const int first = std::countr_zero(packet.active);
    const Vec3 u0 = unit(first);
    const Vec3 o0(packet.org[0][first], packet.org[1][first], packet.org[2][first]);
    for (uint32_t m = packet.active & (packet.active - 1); m; m &= m - 1) {
        const int i = std::countr_zero(m);
        const Vec3 du = unit(i) - u0;
        const Vec3 dor = Vec3(packet.org[0][i], packet.org[1][i], packet.org[2][i]) - o0;
        // Written so that NaN (a zero or non-finite ray) fails the test.
        if (!(dot(du, du) <= max_chord * max_chord && dot(dor, dor) <= max_offset * max_offset)) return false;
    }
    return true;
}

}  // namespace sahara::python
