#include "python/ray_order.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

namespace sahara::python {

namespace {

constexpr int kBitsPerCoordinate = 5;
constexpr int kCells = 1 << kBitsPerCoordinate;
constexpr int kKeyBits = 6 * kBitsPerCoordinate;
/// Three passes order all 30 bits: a million rays fill 2^20 cells, but the order within
/// those cells still shortens traversal by more than the third pass costs.
constexpr int kRadixBits = 10;
constexpr size_t kBuckets = size_t(1) << kRadixBits;

/// The cell of x in [lo, lo + kCells / scale); everything below goes to cell 0, NaN to
/// cell 0 or the last (maxss and minss pass NaN through their first operand).
uint32_t cell(float x, float lo, float scale) {
    const float f = (x - lo) * scale;
    return uint32_t(int(std::min(float(kCells - 1), std::max(f, 0.0f))));  // int: one cvttss2si
}

/// Bit b of a cell index moved to bit 6 b, for all kCells indices: coordinate k's
/// spread bits shifted by k interleave the six coordinates (a Morton code), so nearby
/// codes are nearby in all six.
constexpr std::array<uint32_t, kCells> spread_table() {
    std::array<uint32_t, kCells> t{};
    for (uint32_t v = 0; v < uint32_t(kCells); ++v)
        for (int b = 0; b < kBitsPerCoordinate; ++b) t[v] |= ((v >> b) & 1u) << (6 * b);
    return t;
}
constexpr std::array<uint32_t, kCells> kSpread = spread_table();

/// Rays per block of the key computation: structure-of-arrays blocks let the compiler
/// vectorise the slab test and the cells, the bulk of the work.
constexpr int kKeyBlock = 16;

/// The keys of rays [first, first + count) (count <= kKeyBlock): where each ray's
/// segment [tmin, tmax] enters and leaves `box` (the mesh's bounds), as cells of the
/// box. Rays with nearby entry and exit points are nearly the same line where the mesh
/// is, so they visit the same nodes; keys of origin and direction leave random rays'
/// neighbours far apart inside the box. Rays that miss the box share key 0 (any key is
/// correct: it only orders the work).
void segment_keys(const RayBatch& rays, size_t first, int count, const Bounds3& box, const float (&scale)[3],
                  uint64_t* keys) {
    float org[3][kKeyBlock] = {}, dir[3][kKeyBlock] = {}, enter[kKeyBlock] = {}, leave[kKeyBlock] = {};
    for (int i = 0; i < count; ++i) {
        const size_t j = first + size_t(i);
        if (const float* row = rays.f32_row(j)) {
            for (int k = 0; k < 3; ++k) org[k][i] = row[k], dir[k][i] = row[3 + k];
        } else {
            const Ray r = rays.ray(j);
            for (int k = 0; k < 3; ++k) org[k][i] = r.origin[k], dir[k][i] = r.dir[k];
        }
        enter[i] = rays.tmin(j), leave[i] = rays.tmax(j);
    }
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < kKeyBlock; ++i) {
            const float inv = 1.0f / dir[k][i];
            const float t0 = (box.lo[k] - org[k][i]) * inv, t1 = (box.hi[k] - org[k][i]) * inv;
            // Operand order makes NaN (an origin on a slab plane of a zero component) skipped.
            enter[i] = std::max(enter[i], std::min(t0, t1));
            leave[i] = std::min(leave[i], std::max(t0, t1));
        }
    // The cells in a loop of their own, which vectorises: entry and exit points lie on the
    // box, where clamping to the first or last cell is a coin toss a branch would miss.
    uint32_t cells[6][kKeyBlock];
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < kKeyBlock; ++i) {
            cells[k][i] = cell(org[k][i] + enter[i] * dir[k][i], box.lo[k], scale[k]);
            cells[3 + k][i] = cell(org[k][i] + leave[i] * dir[k][i], box.lo[k], scale[k]);
        }
    for (int i = 0; i < count; ++i) {
        uint32_t code = 0;
        for (int k = 0; k < 6; ++k) code |= kSpread[cells[k][i]] << k;
        keys[i] = uint64_t(enter[i] <= leave[i] ? code : 0u) << 32 | uint64_t(first + size_t(i));
    }
}

/// Morton code (high 32 bits) and batch index (low 32 bits) of every ray.
UninitializedVector<uint64_t> keyed_indices(const RayBatch& rays, const Bounds3& box, int threads) {
    float scale[3];
    for (int k = 0; k < 3; ++k) {
        const float extent = box.hi[k] - box.lo[k];
        scale[k] = extent > 0.0f && std::isfinite(extent) ? float(kCells) / extent : 0.0f;
    }
    const auto n = int64_t(rays.size());
    UninitializedVector<uint64_t> keys(static_cast<size_t>(n));
    const int64_t blocks = (n + kKeyBlock - 1) / kKeyBlock;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t b = 0; b < blocks; ++b) {
        const auto first = size_t(b * kKeyBlock);
        segment_keys(rays, first, int(std::min<int64_t>(kKeyBlock, n - int64_t(first))), box, scale,
                     &keys[first]);
    }
    return keys;
}

/// One stable counting pass of an LSD radix sort on the bits from `shift`: each thread
/// counts and then places one contiguous block of `in`.
void radix_pass(const UninitializedVector<uint64_t>& in, UninitializedVector<uint64_t>& out, int shift,
                int threads) {
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

void sort_rays(const Bounds3& box, int threads, TraceOrder& out) {
    const RayBatch& rays = out.batch;
    const size_t n = rays.size();
    if (n < kMinSortedRays || n > size_t(std::numeric_limits<uint32_t>::max())) return;
    if (threads <= 0) threads = omp_get_max_threads();
    UninitializedVector<uint64_t> keys = keyed_indices(rays, box, threads);
    UninitializedVector<uint64_t> scratch(n);
    for (int shift = 32; shift < 32 + kKeyBits; shift += kRadixBits) {
        radix_pass(keys, scratch, shift, threads);
        keys.swap(scratch);
    }
    out.order.resize(n);
    out.rays.resize(n);
    out.position.resize(n);
    // The batch's rows are read at random here, kGatherAhead rays ahead of their use:
    // a loop with nothing else to do keeps many loads in flight.
    constexpr int64_t kGatherAhead = 48;
    const auto count = int64_t(n);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t k = 0; k < count; ++k) {
        if (k + kGatherAhead < count) rays.prefetch(uint32_t(keys[size_t(k + kGatherAhead)]));
        const auto index = uint32_t(keys[size_t(k)]);
        out.order[size_t(k)] = index;
        out.position[index] = uint32_t(k);
        const Ray r = rays.ray(index);
        out.rays[size_t(k)] = SortedRay{r.origin, r.tmin, r.dir, r.tmax};
    }
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
