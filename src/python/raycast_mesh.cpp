#include "python/raycast_mesh.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <span>

#include "accel/crossings.h"
#include "geometry/triangle.h"
#include "python/ray_order.h"
#include "scene/accelerator.h"
#include "scene/scene.h"

namespace sahara::python {

namespace {

/// Rays per OpenMP work item: large enough to amortise scheduling, small enough that
/// uneven rays (long misses beside early hits) still balance across threads.
constexpr int64_t kRayChunk = 256;

/// Runs of kPacketSize rays take the packet traversal when their unit directions lie
/// within this chord of the first ray's (about 1.7 degrees; a camera's neighbouring
/// pixels are far closer) and their origins within this fraction of the mesh's
/// diagonal. Less coherent packets (sorted random rays) trace faster ray by ray.
constexpr float kPacketMaxChord = 0.03f;
constexpr float kPacketMaxOffset = 0.03f;

/// Sorting pays for itself through the cache: a tree that fits in a core's L2 stays
/// there whatever the ray order, and its rays are too cheap to carry the sort.
constexpr size_t kMinSortedBvhBytes = size_t(2) << 20;

int team_size(const RaySlice& slice) { return slice.threads > 0 ? slice.threads : omp_get_max_threads(); }

/// Work items of a slice: kRayChunk rays, fewer when the slice is short (slow rays make
/// short slices, and every thread should still get several items), in multiples of `unit`.
int64_t work_item(const RaySlice& slice, int threads, int64_t unit) {
    const auto rays = int64_t(slice.last - slice.first);
    const int64_t per_item = std::clamp<int64_t>(rays / (8 * int64_t(threads)), unit, kRayChunk);
    return per_item / unit;
}

}  // namespace

CastMesh::CastMesh(std::vector<Vec3> positions, std::vector<uint32_t> indices) {
    // The Accelerator reads the mesh from a Scene and copies the vertices it tests into
    // its leaf blocks; the arrays move through the Scene and back, never copied.
    Scene scene;
    scene.triangles.positions = std::move(positions);
    scene.triangles.indices = std::move(indices);
    // Crossings count each leaf reference: the tree must reference every triangle once.
    if (scene.triangles.size() > 0)
        accel_ = std::make_unique<Accelerator>(scene, crossings_accelerator_options());
    positions_ = std::move(scene.triangles.positions);
    indices_ = std::move(scene.triangles.indices);
    facts_.resize(triangle_count());
    const auto m = int64_t(facts_.size());
#pragma omp parallel for schedule(static)
    for (int64_t i = 0; i < m; ++i) facts_[size_t(i)] = facts(uint32_t(i));
}

CastMesh::~CastMesh() = default;

size_t CastMesh::bvh_bytes() const { return accel_ ? accel_->bytes() : 0; }

CastMesh::TriangleFacts CastMesh::facts(uint32_t triangle) const {
    const uint32_t* v = &indices_[3 * size_t(triangle)];
    // In double: a sliver's cross product loses most of its bits in float.
    const Vec3d p0(positions_[v[0]]), p1(positions_[v[1]]), p2(positions_[v[2]]);
    const Vec3d n = cross(p1 - p0, p2 - p0);
    const double len = length(n);
    if (!(len > 0.0)) return {Vec3(0.0f), kInfinity};
    // The test's t is a sum of edge functions times vertex depths, divided by their sum
    // (twice the area): its rounding error, relative to t, grows like
    // extent * (extent^2 / area) / t. Below kRefineFactor times that length it is
    // recomputed; beyond, the error is a small fraction of a float rounding.
    constexpr double kRefineFactor = 8.0;
    const double extent = std::max({length(p1 - p0), length(p2 - p1), length(p0 - p2)});
    const double below = kRefineFactor * extent * extent * extent / len;
    return {Vec3(n / len), float(std::min(below, double(kInfinity)))};
}

void CastMesh::refine(const Ray& ray, Hit& hit) const {
    // The watertight test decides which triangle is hit; its t and barycentrics come from
    // sheared edge functions whose rounding grows with the triangle's extent, so on long
    // slivers (skirting boards, CAD strips) a near hit's t can be off by 1e-3 relative.
    // In double, with the float inputs exact, the plane intersection is off by about one
    // float rounding. Where the plane disagrees with the test (a ray along the plane, or
    // a hit the test placed just inside tmin/tmax that the plane puts outside), the
    // test's answer stands.
    const uint32_t tri = prim_index(hit.prim);
    if (!needs_refine(hit.t * length(ray.dir), tri)) return;
    const uint32_t* v = &indices_[3 * size_t(tri)];
    const Vec3d p0(positions_[v[0]]), e1 = Vec3d(positions_[v[1]]) - p0, e2 = Vec3d(positions_[v[2]]) - p0;
    const Vec3d n = cross(e1, e2), o(ray.origin), d(ray.dir);
    const double nd = dot(n, d);
    if (nd == 0.0) return;
    const double t = dot(n, p0 - o) / nd;
    const auto tf = float(t);
    if (!(tf > ray.tmin && tf < ray.tmax)) return;
    const Vec3d q = o + d * t - p0;
    const double nn = dot(n, n);
    // On an edge the plane's barycentrics may dip below 0 by a rounding: clamped, so
    // (u, v) stays in the triangle as the test's did.
    const double b1 = std::max(dot(n, cross(q, e2)) / nn, 0.0), b2 = std::max(dot(n, cross(e1, q)) / nn, 0.0);
    const double sum = std::max(b1 + b2, 1.0);
    hit.t = tf, hit.u = float(b1 / sum), hit.v = float(b2 / sum);
}

void CastMesh::store(size_t k, const Hit& hit, const NearestHits& out) const {
    // Selects, not a branch: after a sort, hits and misses alternate at random.
    const bool found = hit.hit();
    const uint32_t tri = found ? prim_index(hit.prim) : 0;
    const Vec3 nrm = found ? facts_[tri].normal : Vec3(0.0f);
    out.t[k] = found ? hit.t : kInfinity;
    out.prim[k] = found ? int64_t(tri) : int64_t(-1);
    out.uv[2 * k] = found ? hit.u : 0.0f;
    out.uv[2 * k + 1] = found ? hit.v : 0.0f;
    out.normal[3 * k] = nrm.x;
    out.normal[3 * k + 1] = nrm.y;
    out.normal[3 * k + 2] = nrm.z;
}

float CastMesh::packet_max_offset() const {
    if (!accel_) return 0.0f;
    const Bounds3 box = accel_->bounds();
    return kPacketMaxOffset * length(box.hi - box.lo);
}

TraceOrder CastMesh::trace_order(const RayBatch& rays, int threads) const {
    SortBuffers reuse;
    {
        const std::lock_guard lock(spare_mutex_);
        reuse = std::move(spare_);
    }
    TraceOrder out(rays, std::move(reuse));
    if (!accel_ || accel_->bytes() < kMinSortedBvhBytes || rays.size() < kMinSortedRays ||
        runs_are_coherent(rays, kPacketMaxChord, packet_max_offset()))
        return out;
    sort_rays(accel_->bounds(), threads, out);
    if (out.sorted()) resize_unwritten(out.hits, out.keys.size());
    return out;
}

void CastMesh::recycle(TraceOrder&& order) const {
    const size_t bytes = order.bytes();
    if (bytes > kMaxKeptSortBytes) return;
    const std::lock_guard lock(spare_mutex_);
    if (bytes > spare_.bytes()) spare_ = std::move(static_cast<SortBuffers&>(order));
}

void CastMesh::write_sorted_hits(const TraceOrder& rays, int threads, const NearestHits& out) const {
    if (!rays.sorted()) return;
    const auto n = int64_t(rays.keys.size());
    const int team = threads > 0 ? threads : omp_get_max_threads();
    const uint32_t* slot_of = rays.slot_of.data();
    const SortedHit* hits = rays.hits.data();
    // The hits come from one sequential stream per bucket, too many streams for the
    // hardware prefetcher: they are prefetched kHitsAhead rays ahead, and the facts of
    // a hit's triangle (a table of the mesh's size, read at random) half as far ahead.
    constexpr int64_t kHitsAhead = 32;
    // Dynamic: on a shared machine a thread held back delays the pass by one chunk only.
    constexpr int64_t kResultChunk = 16384;
#pragma omp parallel for schedule(dynamic, kResultChunk) num_threads(team)
    for (int64_t i = 0; i < n; ++i) {
        if (i + kHitsAhead < n) __builtin_prefetch(&hits[slot_of[size_t(i + kHitsAhead)]]);
        if (i + kHitsAhead / 2 < n) {
            const SortedHit& ahead = hits[slot_of[size_t(i + kHitsAhead / 2)]];
            if (ahead.prim != kNoPrim) __builtin_prefetch(&facts_[prim_index(ahead.prim)]);
        }
        const SortedHit& h = hits[slot_of[size_t(i)]];
        Hit hit;
        hit.t = h.t, hit.prim = h.prim, hit.u = h.u, hit.v = h.v;
        // The batch's ray is read only for the few hits refine changes.
        if (hit.hit() && needs_refine(h.t * h.dir_length, prim_index(h.prim)))
            refine(rays.batch.ray(size_t(i)), hit);
        store(size_t(i), hit, out);
    }
}

void CastMesh::nearest_sorted(TraceOrder& rays, RaySlice slice) const {
    const auto first = int64_t(slice.first), last = int64_t(slice.last);
    const int threads = team_size(slice);
    const int64_t item = work_item(slice, threads, 1);
    const SortedRay* in = rays.rays.data();
    const uint64_t* keys = rays.keys.data();
    SortedHit* hits = rays.hits.data();
    // The copies of a bucket are read in its sorted order, at random within the bucket's
    // few tens of kB: asked for a few rays ahead, as the hardware prefetcher cannot guess.
    constexpr int64_t kRaysAhead = 8;
#pragma omp parallel for schedule(dynamic, item) num_threads(threads)
    for (int64_t k = first; k < last; ++k) {
        if (k + kRaysAhead < last) __builtin_prefetch(&in[uint32_t(keys[k + kRaysAhead])]);
        const uint32_t slot = uint32_t(keys[k]);
        Ray r = in[slot].ray();
        Hit h;
        if (accel_) accel_->intersect(r, h);
        // Refined in write_sorted_hits, which reads the triangle's row anyway.
        hits[slot] = SortedHit{h.t, h.prim, h.u, h.v, length(r.dir)};
    }
}

void CastMesh::nearest(TraceOrder& rays, RaySlice slice, const NearestHits& out) const {
    if (rays.sorted()) return nearest_sorted(rays, slice);
    const auto first = int64_t(slice.first), last = int64_t(slice.last);
    if (!accel_) {
        for (int64_t k = first; k < last; ++k) store(size_t(k), Hit{}, out);
        return;
    }
    const float max_offset = packet_max_offset();
    const int64_t packets = (last - first + kPacketSize - 1) / kPacketSize;
    const int threads = team_size(slice);
    const int64_t item = work_item(slice, threads, kPacketSize);
#pragma omp parallel for schedule(dynamic, item) num_threads(threads)
    for (int64_t p = 0; p < packets; ++p) {
        RayPacket packet;
        HitPacket hits;
        const int64_t start = first + p * kPacketSize;
        const int lanes = int(std::min<int64_t>(kPacketSize, last - start));
        for (int l = 0; l < lanes; ++l) packet.set(l, rays.ray(size_t(start + l)));
        if (lanes > 1 && packet_is_coherent(packet, kPacketMaxChord, max_offset)) {
            accel_->intersect_packet(packet, hits);
            for (int l = 0; l < lanes; ++l) {
                Hit h = hits.hit(l);
                if (h.hit()) refine(rays.ray(size_t(start + l)), h);
                store(size_t(start + l), h, out);
            }
            continue;
        }
        for (int l = 0; l < lanes; ++l) {
            const Ray ray = packet.ray(l);
            Ray r = ray;
            Hit h;
            if (accel_->intersect(r, h)) refine(ray, h);
            store(size_t(start + l), h, out);
        }
    }
}

void CastMesh::occluded(const TraceOrder& rays, RaySlice slice, bool* out) const {
    const auto first = int64_t(slice.first), last = int64_t(slice.last);
    const int threads = team_size(slice);
    const int64_t item = work_item(slice, threads, 1);
#pragma omp parallel for schedule(dynamic, item) num_threads(threads)
    for (int64_t k = first; k < last; ++k) {
        out[rays.index_of(size_t(k))] = accel_ && accel_->occluded(rays.ray(size_t(k)));
    }
}

void CastMesh::count_crossings(const RayBatch& rays, int32_t* out) const {
    const auto n = int64_t(rays.size());
    const std::span<const TriangleBlock4> blocks =
        accel_ ? std::span<const TriangleBlock4>(accel_->leaf_blocks()) : std::span<const TriangleBlock4>();
#pragma omp parallel for schedule(dynamic, kRayChunk)
    for (int64_t i = 0; i < n; ++i)
        out[i] = accel_ ? int32_t(sahara::count_crossings(accel_->bvh8(), blocks, rays.ray(size_t(i)))) : 0;
}

Crossings CastMesh::crossings(const RayBatch& rays) const {
    Crossings out;
    if (!accel_) return out;
    const std::span<const TriangleBlock4> blocks(accel_->leaf_blocks());
    // Each chunk of rays collects its sorted crossings on its own; a prefix sum over the
    // chunks then places them, so the result does not depend on the thread count.
    const auto n = int64_t(rays.size());
    const int64_t chunks = (n + kRayChunk - 1) / kRayChunk;
    out.hits.resize(size_t(chunks));
    out.ray_of.resize(size_t(chunks));
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t c = 0; c < chunks; ++c) {
        auto& h = out.hits[size_t(c)];
        auto& r = out.ray_of[size_t(c)];
        for (int64_t i = c * kRayChunk; i < std::min(n, (c + 1) * kRayChunk); ++i) {
            const size_t first = h.size();
            const Ray ray = rays.ray(size_t(i));
            collect_crossings(accel_->bvh8(), blocks, ray, h);
            // The same t and barycentrics as cast_rays gives for the nearest crossing.
            for (size_t k = first; k < h.size(); ++k) refine(ray, h[k]);
            std::sort(h.begin() + ptrdiff_t(first), h.end(), [](const Hit& a, const Hit& b) {
                return a.t < b.t || (a.t == b.t && a.prim < b.prim);
            });
            r.resize(h.size(), i);
        }
    }
    out.offset.assign(size_t(chunks) + 1, 0);
    for (size_t c = 0; c < size_t(chunks); ++c) out.offset[c + 1] = out.offset[c] + out.hits[c].size();
    return out;
}

void Crossings::write(int64_t* ray, int64_t* prim, float* t, float* uv) const {
    const auto chunks = int64_t(hits.size());
#pragma omp parallel for schedule(static)
    for (int64_t c = 0; c < chunks; ++c)
        for (size_t j = 0; j < hits[size_t(c)].size(); ++j) {
            const Hit& h = hits[size_t(c)][j];
            const size_t k = offset[size_t(c)] + j;
            ray[k] = ray_of[size_t(c)][j];
            prim[k] = int64_t(prim_index(h.prim));
            t[k] = h.t;
            uv[2 * k] = h.u;
            uv[2 * k + 1] = h.v;
        }
}

}  // namespace sahara::python
