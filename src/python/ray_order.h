#pragma once
/// The order in which RayCaster traces a batch: rays sorted so that neighbours in
/// the order start near each other and point the same way. Consecutive rays then
/// walk mostly the same nodes and leaves, which stay in the cache, and coherent
/// runs (a camera's rays) can go through the packet traversal. Results are still
/// written at each ray's own index.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "accel/bvh.h"
#include "accel/packet.h"
#include "geometry/hit.h"
#include "math/bounds.h"
#include "python/raycast_arrays.h"

namespace sahara::python {

/// Batches shorter than this are traced in their own order: the rays are too
/// sparse for neighbours to share much, and the sort would cost more than it saves.
inline constexpr size_t kMinSortedRays = size_t(1) << 14;

/// A vector whose resize() leaves new elements unwritten, on 2 MB pages when large
/// (accel/bvh.h's FillLaterAllocator): the sort's buffers (tens of MB for a million
/// rays) are written in full by parallel loops, which then take their first touch in
/// parallel instead of one thread zeroing them first, and the bucket pass, which writes
/// to a thousand places at once, does not miss the TLB on each write.
template <class T>
using UninitializedVector = std::vector<T, FillLaterAllocator<T, 64>>;

/// Sizes `v` to n unwritten elements, its old ones dropped: storage with room is kept,
/// and storage without is replaced with nothing copied.
template <class T>
void resize_unwritten(UninitializedVector<T>& v, size_t n) {
    v.clear();
    v.resize(n);
}

/// A ray as the sorted traversal reads it: half a cache line, so a sequential walk
/// over the sorted copies loads two rays per line.
/// Plain floats, not Vec3: Vec3 zero-initialises, and sizing the buffer of a million
/// copies would then write 32 MB of zeros on one thread before every sort. Origin and
/// direction in a row, as in a float32 batch row and in Ray, so each copies as a block.
struct alignas(32) SortedRay {
    float origin[3];
    float dir[3];
    float tmin;
    float tmax;
    Ray ray() const {
        Ray r;
        r.origin = Vec3(origin[0], origin[1], origin[2]), r.dir = Vec3(dir[0], dir[1], dir[2]);
        r.tmin = tmin, r.tmax = tmax;
        return r;
    }
};
static_assert(sizeof(SortedRay) == 32);
static_assert(std::is_trivially_default_constructible_v<SortedRay> && offsetof(SortedRay, dir) == 12);

/// A nearest hit as it waits in sorted order for the write-back: Hit without its
/// instance field, with the length of the ray's direction (20 bytes).
struct SortedHit {
    float t;
    uint32_t prim;
    float u, v;
    float dir_length;  ///< of the ray's direction: refine's test needs the hit's distance
};
static_assert(std::is_trivially_default_constructible_v<SortedHit>);

/// The arrays of a sorted order (TraceOrder), which a caster keeps for its next batch
/// (CastMesh::trace_order): reused, they are neither allocated nor cleared by the
/// kernel again, which otherwise zero-fills tens of MB per million rays.
struct SortBuffers {
    /// code << 32 | slot, in traced order (empty: the batch's own order).
    UninitializedVector<uint64_t> keys;
    /// code << 32 | batch index in batch order, then each bucket's sort scratch.
    UninitializedVector<uint64_t> scratch;
    UninitializedVector<uint32_t> index;    ///< the batch index of each slot
    UninitializedVector<uint32_t> slot_of;  ///< the slot of each batch index
    UninitializedVector<SortedRay> rays;    ///< the ray copies by slot
    /// Nearest hits by slot: a bucket's hits are written while its rays are traced,
    /// then read back in batch order as one sequential stream per bucket.
    UninitializedVector<SortedHit> hits;

    /// Bytes held (capacities).
    size_t bytes() const;
};

/// The rays a query traces, in the order it traces them: the batch itself, or the
/// batch sorted (sort_rays). The sort copies each ray once, to a slot of its top
/// bucket (contiguous per bucket), and then sorts each bucket's keys in the cache;
/// position k traces the ray in slot slot(k), which lies in the same bucket as the
/// slots around it, so the tracer reads one bucket's copies (a few tens of kB) at a
/// time. Results go back the same way (by slot, then slot_of each batch index), so
/// neither direction reads or writes one cache line per ray at random.
struct TraceOrder : SortBuffers {
    /// The batch in its own order, with `reuse`'s storage for a sort.
    TraceOrder(const RayBatch& rays, SortBuffers&& reuse) : SortBuffers(std::move(reuse)), batch(rays) {
        keys.clear();
    }

    const RayBatch& batch;

    bool sorted() const { return !keys.empty(); }
    size_t size() const { return batch.size(); }
    /// The slot of position k (sorted orders only).
    uint32_t slot(size_t k) const { return uint32_t(keys[k]); }
    Ray ray(size_t k) const { return sorted() ? rays[slot(k)].ray() : batch.ray(k); }
    /// The batch index of position k (where its result goes).
    size_t index_of(size_t k) const { return sorted() ? size_t(index[slot(k)]) : k; }
};

/// Sorts the batch's rays into `out` (keys, index, slot_of, rays) by a Morton code of the
/// points where each ray enters and leaves `box` (the mesh's bounds; 5 bits per
/// coordinate, 30 in all), ties in batch order. Leaves `out` unsorted below
/// kMinSortedRays or at 2^32 rays and more. OpenMP on `threads` (0: all).
void sort_rays(const Bounds3& box, int threads, TraceOrder& out);

/// Whether the active rays of a packet are close enough for the packet traversal to
/// beat tracing them one by one: unit directions within `max_chord` of the first
/// ray's and origins within `max_offset` of its origin.
bool packet_is_coherent(const RayPacket& packet, float max_chord, float max_offset);

/// Whether most runs of kPacketSize consecutive rays of the batch are coherent
/// (packet_is_coherent), judged from a sample of runs spread over the batch: such
/// a batch (a camera's rays in image order) is traced in its own order.
bool runs_are_coherent(const RayBatch& rays, float max_chord, float max_offset);

}  // namespace sahara::python
