#include "python/ray_order.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "accel/simd_path.h"

namespace sahara::python {

namespace {

/// Bits of each coordinate of the entry point and of the exit point in the key.
constexpr int kEntryBits = 5;
constexpr int kExitBits = 5;
static_assert(kExitBits <= kEntryBits);
constexpr int kCells = 1 << kEntryBits;
constexpr int kKeyBits = 3 * (kEntryBits + kExitBits);
/// Three digits order all 30 bits (one global pass, two within each top bucket): a million
/// rays fill 2^20 cells, but the order within those cells still shortens traversal.
constexpr int kRadixBits = 10;
static_assert(kKeyBits == 3 * kRadixBits);
constexpr size_t kBuckets = size_t(1) << kRadixBits;
/// Chunks of the batch per thread in the key and bucket passes.
constexpr int kChunksPerThread = 8;

/// The cell of x in [lo, lo + kCells / scale); everything below goes to cell 0, NaN to
/// cell 0 or the last (maxss and minss pass NaN through their first operand).
[[gnu::always_inline]] inline uint32_t cell(float x, float lo, float scale) {
    const float f = (x - lo) * scale;
    return uint32_t(int(std::min(float(kCells - 1), std::max(f, 0.0f))));  // int: one cvttss2si
}

/// Where each bit of the six cell indices goes in the key: level by level from the
/// most significant, the entry point's x, y, z and then, on the exit point's
/// kExitBits lowest levels, its x, y, z (a Morton code of the six, so nearby codes are
/// nearby in all six). Table [k][cell] for coordinate k of the entry point (k < 3) or
/// of the exit point (k >= 3; index: the cell at the entry point's resolution).
/// Entry before exit within a level: the sorted rays then miss the L1 cache less
/// while they are traced than with the exit point's bits first (docs/performance.md).
constexpr std::array<std::array<uint32_t, kCells>, 6> spread_tables() {
    std::array<std::array<uint32_t, kCells>, 6> t{};
    int bit = kKeyBits;
    for (int level = kEntryBits - 1; level >= 0; --level)
        for (int k = 0; k < 6; ++k) {
            const bool exit = k >= 3;
            if (exit && level >= kExitBits) continue;
            --bit;
            const int shift = exit ? level + (kEntryBits - kExitBits) : level;
            for (uint32_t v = 0; v < uint32_t(kCells); ++v) t[size_t(k)][v] |= ((v >> shift) & 1u) << bit;
        }
    return t;
}
constexpr auto kSpread = spread_tables();

/// Rays per block of the key computation: structure-of-arrays blocks let the compiler
/// vectorise the slab test and the cells, the bulk of the work.
constexpr int kKeyBlock = 16;

/// The keys of rays [first, first + count) (count <= kKeyBlock): where each ray's
/// segment [tmin, tmax] enters and leaves `box` (the mesh's bounds), as cells of the
/// box. Rays with nearby entry and exit points are nearly the same line where the mesh
/// is, so they visit the same nodes; keys of origin and direction leave random rays'
/// neighbours far apart inside the box. Rays that miss the box share key 0 (any key is
/// correct: it only orders the work).
[[gnu::always_inline]] inline void segment_keys(const RayBatch& rays, size_t first, int count,
                                                const Bounds3& box, const float (&scale)[3], uint64_t* keys) {
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
        for (int k = 0; k < 6; ++k) code |= kSpread[size_t(k)][cells[k][i]];
        keys[i] = uint64_t(enter[i] <= leave[i] ? code : 0u) << 32 | uint64_t(first + size_t(i));
    }
}

/// The scale of each axis of `box` onto kCells cells (0 for an empty or unbounded axis).
void cell_scales(const Bounds3& box, float (&scale)[3]) {
    for (int k = 0; k < 3; ++k) {
        const float extent = box.hi[k] - box.lo[k];
        scale[k] = extent > 0.0f && std::isfinite(extent) ? float(kCells) / extent : 0.0f;
    }
}

/// The top kRadixBits of a key's code: the bucket of the first, global pass.
size_t top_bucket(uint64_t key) { return size_t(key >> (32 + kKeyBits - kRadixBits)); }

/// The sort's working arrays besides TraceOrder's. The first pass moves each ray's
/// key and its copy to the key's top bucket (reading the batch in order, so without
/// scattered reads); each bucket, about a thousand rays per million that stay in the
/// cache, then has its keys sorted on their own by the remaining bits (TraceOrder's
/// `scratch` holding the batch-order keys first, then each bucket's sort scratch). The
/// copies are not moved again: the tracer reads them through the sorted keys' slots.
struct SortScratch {
    std::vector<size_t> counts;        ///< per chunk and top bucket, then each chunk's slots
    std::vector<size_t> bucket_start;  ///< kBuckets + 1 entries
};

/// Keys of rays [lo, hi) and their counts per top bucket.
[[gnu::always_inline]] inline void key_range_body(const RayBatch& rays, size_t lo, size_t hi,
                                                  const Bounds3& box, const float (&scale)[3], uint64_t* keys,
                                                  size_t* count) {
    for (size_t first = lo; first < hi; first += kKeyBlock)
        segment_keys(rays, first, int(std::min<size_t>(kKeyBlock, hi - first)), box, scale, &keys[first]);
    for (size_t i = lo; i < hi; ++i) ++count[top_bucket(keys[i])];
}

/// key_range_body for the baseline and, 8 lanes per step, for AVX2 (the key's arithmetic
/// is the same IEEE operations either way, with no contraction into FMA).
void key_range_sse2(const RayBatch& rays, size_t lo, size_t hi, const Bounds3& box, const float (&scale)[3],
                    uint64_t* keys, size_t* count) {
    key_range_body(rays, lo, hi, box, scale, keys, count);
}
__attribute__((target("avx2"))) void key_range_avx2(const RayBatch& rays, size_t lo, size_t hi,
                                                    const Bounds3& box, const float (&scale)[3],
                                                    uint64_t* keys, size_t* count) {
    key_range_body(rays, lo, hi, box, scale, keys, count);
}

/// Bucket by bucket, chunk by chunk: each chunk's first slot in each bucket (the
/// pass stays stable), and where each bucket starts.
void place_buckets(SortScratch& s, size_t chunks) {
    size_t next = 0;
    for (size_t bucket = 0; bucket < kBuckets; ++bucket) {
        s.bucket_start[bucket] = next;
        for (size_t u = 0; u < chunks; ++u) {
            const size_t c = s.counts[u * kBuckets + bucket];
            s.counts[u * kBuckets + bucket] = next;
            next += c;
        }
    }
    s.bucket_start[kBuckets] = next;
}

/// Moves rays [lo, hi) to their top buckets: key (low half now the bucketed slot),
/// batch index and ray copy; records each ray's slot.
void bucket_range(const RayBatch& rays, size_t lo, size_t hi, size_t* count, TraceOrder& out) {
    // float32 rows are copied as they are; other layouts go through the converting reader.
    const bool f32 = lo < hi && rays.f32_row(lo) != nullptr;
    for (size_t i = lo; i < hi; ++i) {
        const uint64_t key = out.scratch[i];
        const size_t slot = count[top_bucket(key)]++;
        out.keys[slot] = (key & ~uint64_t(0xFFFFFFFFu)) | uint64_t(slot);
        out.index[slot] = uint32_t(key);
        out.slot_of[i] = uint32_t(slot);
        SortedRay& r = out.rays[slot];
        if (f32) {
            std::memcpy(&r, rays.f32_row(i), 6 * sizeof(float));  // origin and direction
            r.tmin = rays.tmin(i), r.tmax = rays.tmax(i);
        } else {
            const Ray full = rays.ray(i);
            r = SortedRay{{full.origin.x, full.origin.y, full.origin.z},
                          {full.dir.x, full.dir.y, full.dir.z},
                          full.tmin,
                          full.tmax};
        }
    }
}

/// Sorts one top bucket's keys [lo, hi) by the code's lower bits (two stable counting
/// passes through `tmp`).
void sort_bucket(uint64_t* keys, size_t n, uint64_t* tmp) {
    if (n < 2) return;
    uint32_t count[2][kBuckets] = {};
    for (size_t i = 0; i < n; ++i) {
        ++count[0][(keys[i] >> 32) & (kBuckets - 1)];
        ++count[1][(keys[i] >> (32 + kRadixBits)) & (kBuckets - 1)];
    }
    for (auto& c : count) {
        uint32_t next = 0;
        for (uint32_t& x : c) next += std::exchange(x, next);
    }
    for (size_t i = 0; i < n; ++i) tmp[count[0][(keys[i] >> 32) & (kBuckets - 1)]++] = keys[i];
    for (size_t i = 0; i < n; ++i) keys[count[1][(tmp[i] >> (32 + kRadixBits)) & (kBuckets - 1)]++] = tmp[i];
}

}  // namespace

void sort_rays(const Bounds3& box, int threads, TraceOrder& out) {
    const RayBatch& rays = out.batch;
    const size_t n = rays.size();
    if (n < kMinSortedRays || n > size_t(std::numeric_limits<uint32_t>::max())) return;
    if (threads <= 0) threads = omp_get_max_threads();
    float scale[3];
    cell_scales(box, scale);
    SortScratch s;
    const bool avx2 = active_simd_path() != SimdPath::sse2;
    // More chunks than threads, taken dynamically: a thread the system holds back
    // (a shared machine) then delays the passes by one chunk, not by half the batch.
    const size_t chunks = std::min(n, size_t(kChunksPerThread) * size_t(threads));
    s.counts.assign(chunks * kBuckets, 0);
    s.bucket_start.resize(kBuckets + 1);
    for (auto* v : {&out.keys, &out.scratch}) resize_unwritten(*v, n);
    for (auto* v : {&out.index, &out.slot_of}) resize_unwritten(*v, n);
    resize_unwritten(out.rays, n);
    const auto chunk_count = int64_t(chunks);
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(dynamic, 1)
        for (int64_t c = 0; c < chunk_count; ++c)
            (avx2 ? key_range_avx2 : key_range_sse2)(rays, n * size_t(c) / chunks, n * size_t(c + 1) / chunks,
                                                     box, scale, out.scratch.data(),
                                                     &s.counts[size_t(c) * kBuckets]);
#pragma omp single
        place_buckets(s, chunks);
#pragma omp for schedule(dynamic, 1)
        for (int64_t c = 0; c < chunk_count; ++c)
            bucket_range(rays, n * size_t(c) / chunks, n * size_t(c + 1) / chunks,
                         &s.counts[size_t(c) * kBuckets], out);
#pragma omp for schedule(dynamic, 4)
        for (size_t bucket = 0; bucket < kBuckets; ++bucket) {
            const size_t lo = s.bucket_start[bucket], hi = s.bucket_start[bucket + 1];
            sort_bucket(out.keys.data() + lo, hi - lo, out.scratch.data() + lo);
        }
    }
}

size_t SortBuffers::bytes() const {
    return keys.capacity() * sizeof(uint64_t) + scratch.capacity() * sizeof(uint64_t) +
           index.capacity() * sizeof(uint32_t) + slot_of.capacity() * sizeof(uint32_t) +
           rays.capacity() * sizeof(SortedRay) + hits.capacity() * sizeof(SortedHit);
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
