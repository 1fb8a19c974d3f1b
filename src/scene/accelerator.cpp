#include "scene/accelerator.h"

#include <unistd.h>
#include <xmmintrin.h>
#include <emmintrin.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "accel/build_team.h"
#include "base/error.h"
#include "base/process_usage.h"
#include "geometry/spawn.h"
#include "scene/leaf_blocks.inl"
#include "scene/scene.h"

namespace sahara {

/// Leaf slot s's primitive id: the builder's primitive bvh.prim_indices[s].
struct SlotIds {
    const BuildArray<uint32_t>& ids;
    const std::vector<uint32_t>& prim_of_slot;
    size_t size() const { return prim_of_slot.size(); }
    uint32_t operator[](size_t s) const { return ids[prim_of_slot[s]]; }
};

namespace {

/// Loops over fewer items than this stay serial (a parallel region costs more).
constexpr int64_t kParallelLoopMin = 8192;

/// The builder's view of the scene: one box, one centre and one id per primitive.
/// Uninitialised arrays (BuildArray), each element written once by the thread that
/// computes it.
struct PrimitiveList {
    BuildArray<Bounds3> boxes;
    BuildArray<Vec3> centers;
    BuildArray<uint32_t> ids;

    explicit PrimitiveList(size_t n) : boxes(n), centers(n), ids(n) {}
    size_t size() const { return ids.size(); }
    std::span<const Bounds3> box_span() const { return {boxes.get(), boxes.size()}; }
    std::span<const Vec3> center_span() const { return {centers.get(), centers.size()}; }

    void set(size_t k, const Bounds3& b, uint32_t id) const {
        // A primitive with non-finite coordinates can never be hit; give it an
        // empty box (ignored by node bounds) and a harmless centre.
        const bool finite = is_finite(b.lo) && is_finite(b.hi);
        boxes[k] = finite ? b : Bounds3{};
        centers[k] = finite ? b.center() : Vec3(0.0f);
        ids[k] = id;
    }

    /// set() for triangle i, in SSE: the same minima, maxima and centre bit for bit
    /// (_mm_min_ps(p, lo) is std::min(lo, p), NaN coordinates skipped alike).
    void set_triangle(const TriangleSoup& soup, uint32_t i) const {
        const uint32_t* v = &soup.indices[3 * size_t(i)];
        __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
        for (int k = 0; k < 3; ++k) {
            const Vec3& p = soup.positions[v[k]];
            const __m128 q = _mm_setr_ps(p.x, p.y, p.z, 0.0f);
            lo = _mm_min_ps(q, lo);
            hi = _mm_max_ps(q, hi);
        }
        const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)), inf = _mm_set1_ps(kInfinity);
        const __m128 finite = _mm_and_ps(_mm_cmplt_ps(_mm_and_ps(lo, abs_mask), inf),
                                         _mm_cmplt_ps(_mm_and_ps(hi, abs_mask), inf));
        if ((_mm_movemask_ps(finite) & 7) != 7) {
            set(i, Bounds3{}, make_prim_id(PrimKind::triangle, i));
            return;
        }
        alignas(16) float l[4], h[4], c[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        _mm_store_ps(c, _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f)));
        boxes[i] = Bounds3{{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
        centers[i] = Vec3(c[0], c[1], c[2]);
        ids[i] = make_prim_id(PrimKind::triangle, i);
    }
};

PrimitiveList collect_primitives(const Scene& scene) {
    const TriangleSoup& soup = scene.triangles;
    const size_t n = soup.size() + scene.spheres.size() + scene.boxes.size() + scene.quadrics.size();
    PrimitiveList list(n);
    const auto triangles = int64_t(soup.size());
    // Tasks of the build's team (Accelerator::build).
#pragma omp taskloop default(shared) grainsize(kParallelLoopMin) if (triangles > kParallelLoopMin)
    for (int64_t i = 0; i < triangles; ++i) list.set_triangle(soup, uint32_t(i));
    size_t k = soup.size();
    for (uint32_t i = 0; i < scene.spheres.size(); ++i)
        list.set(k++, scene.spheres[i].bounds(scene.camera.shutter_open, scene.camera.shutter_close),
                 make_prim_id(PrimKind::sphere, i));
    for (uint32_t i = 0; i < scene.boxes.size(); ++i)
        list.set(k++, scene.boxes[i].bounds(), make_prim_id(PrimKind::box, i));
    for (uint32_t i = 0; i < scene.quadrics.size(); ++i)
        list.set(k++, scene.quadrics[i].bounds(), make_prim_id(PrimKind::quadric, i));
    return list;
}

/// BvhBuilder::automatic resolved for `primitives` (see choose_bvh_builder);
/// largest_share() is asked only for a long render.
BvhBuilder resolve_builder(size_t primitives, const AcceleratorOptions& options,
                           const std::function<double()>& largest_share) {
    if (options.builder != BvhBuilder::automatic) return options.builder;
    BvhWorkload w;
    w.primitives = primitives;
    w.expected_rays = options.expected_rays;
    if (w.expected_rays >= kAutoMinRaysPerPrimitive * double(w.primitives)) w.largest_share = largest_share();
    return choose_bvh_builder(w);
}

/// Bytes of L2 cache per core (1 MiB when the system does not say).
size_t l2_cache_bytes() {
    const long bytes = sysconf(_SC_LEVEL2_CACHE_SIZE);
    return bytes > 0 ? size_t(bytes) : size_t(1) << 20;
}

/// The flat loop: one root leaf over every primitive.
Bvh single_leaf_bvh(const PrimitiveList& prims) {
    Bvh bvh;
    const auto n = uint32_t(prims.size());
    if (n == 0) return bvh;
    Bounds3 all;
    for (const Bounds3& b : prims.box_span()) all.extend(b);
    BvhNode root{};
    root.set_box(all);
    root.index = 0;
    root.count = n;
    bvh.nodes.push_back(root);
    for (uint32_t i = 0; i < n; ++i) bvh.prim_indices.push_back(i);
    return bvh;
}

/// Non-triangle slots get consecutive entries of others_ in slot order: the rank of
/// each among them (fixed before the parallel fill, so the result does not depend on
/// the threads); empty when every slot is a triangle.
std::vector<uint32_t> other_slot_ranks(const SlotIds& ids, bool has_others, size_t& other_count) {
    other_count = 0;
    std::vector<uint32_t> rank;
    if (!has_others) return rank;
    for (size_t s = 0; s < ids.size(); ++s) other_count += prim_kind(ids[s]) != PrimKind::triangle;
    if (other_count) {
        rank.resize(ids.size());
        uint32_t k = 0;
        for (size_t s = 0; s < ids.size(); ++s)
            if (prim_kind(ids[s]) != PrimKind::triangle) rank[s] = k++;
    }
    return rank;
}

/// Vertices of triangle `id` (a triangle's prim id).
TriangleVerts triangle_verts(const TriangleSoup& soup, uint32_t id) {
    const uint32_t* v = &soup.indices[3 * size_t(prim_index(id))];
    return TriangleVerts::of(soup.positions[v[0]], soup.positions[v[1]], soup.positions[v[2]]);
}

}  // namespace

const char* bvh_layout_name(BvhLayout layout) {
    switch (layout) {
        case BvhLayout::pairs:
            return "pairs";
        case BvhLayout::wide8:
            break;
    }
    return "wide8";
}

bool parse_bvh_layout(std::string_view text, BvhLayout& out) {
    if (text == "pairs")
        out = BvhLayout::pairs;
    else if (text == "wide8")
        out = BvhLayout::wide8;
    else
        return false;
    return true;
}

void check_accelerator_capacity(size_t total, size_t largest_kind, BvhLayout layout) {
    const size_t per_kind = size_t(kPrimIndexMask) + 1;
    if (largest_kind > per_kind)
        throw InputError("scene too large: " + std::to_string(largest_kind) +
                         " primitives of one kind, more than the " + std::to_string(per_kind) +
                         " that primitive ids index");
    // make_bvh_wide checks again after the build: the slots, not the primitives, count there.
    const size_t wide_slots = size_t(kMaxWideLeafFirst) + 1;
    if (layout != BvhLayout::pairs && total > wide_slots)
        throw InputError("scene too large: " + std::to_string(total) + " primitives, more than the " +
                         std::to_string(wide_slots) +
                         " that a wide BVH's leaf references reach (the pairs layout has none)");
}

bool automatic_node_pairing(size_t tree_bytes, size_t cache_bytes, bool interior) {
    return tree_bytes > cache_bytes && !interior;
}

Accelerator::Accelerator(const Scene& scene, const AcceleratorOptions& options)
    : spheres_(scene.spheres),
      boxes_(scene.boxes),
      quadrics_(scene.quadrics),
      alpha_(scene),
      one_sided_(one_sided_triangles(scene)) {
    one_sided_count_ = size_t(std::count(one_sided_.begin(), one_sided_.end(), uint8_t(1)));
    check_accelerator_capacity(
        scene.triangles.size() + scene.spheres.size() + scene.boxes.size() + scene.quadrics.size(),
        std::max({scene.triangles.size(), scene.spheres.size(), scene.boxes.size(), scene.quadrics.size()}),
        options.layout);
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = process_cpu_ms();
    build(scene, options);
    build_cpu_ms_ = process_cpu_ms() - cpu_start;
    build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void Accelerator::build(const Scene& scene, const AcceleratorOptions& options) {
    const size_t count =
        scene.triangles.size() + scene.spheres.size() + scene.boxes.size() + scene.quadrics.size();
    // One team for every stage (accel/build_team.h): the primitive boxes, the largest-box
    // share, the binary tree, its collapse and the leaf storage.
    build::with_build_team([&] { build_stages(scene, options); },
                           count > options.flat_loop_max_prims && int64_t(count) > kParallelLoopMin);
}

void Accelerator::build_stages(const Scene& scene, const AcceleratorOptions& options) {
    // Each phase below takes its arrays from the memory the phases before it freed.
    const HugeBlockReuse reuse;
    const PrimitiveList prims = collect_primitives(scene);
    uses_tree_ = prims.size() > options.flat_loop_max_prims;
    const BvhBuildParams params = options.build_params();
    const BvhBuildInput input{prims.box_span(), prims.center_span(), scene.triangles.positions,
                              scene.triangles.indices};
    // One pass over every box, which the builder choice and node pairing may both ask for.
    // Both only compare it with kAutoMinLargestShare (looks_like_interior), so a bound below
    // that serves as well as the share.
    std::optional<double> share;
    const std::function<double()> largest_share = [&] {
        if (!share) share = largest_box_area_share(prims.box_span(), kAutoMinLargestShare);
        return *share;
    };
    builder_ = resolve_builder(prims.size(), options, largest_share);
    layout_ = options.layout;
    bvh_ = uses_tree_ ? build_bvh(input, builder_, params) : single_leaf_bvh(prims);
    // Leaf-ordered primitive data: slot s holds primitive bvh_.prim_indices[s], written
    // straight from the scene into the layout's leaf storage.
    const SlotIds ids{prims.ids, bvh_.prim_indices};
    const bool has_others = prims.size() > scene.triangles.size();
    // Node pairing below asks for the share when the tree outgrows the cache, which the leaf
    // blocks alone (at least one per four slots) may already show: then a task computes it
    // while this thread emits the wide nodes, a serial pass.
    const size_t least_block_bytes = (bvh_.prim_indices.size() + 3) / 4 * sizeof(TriangleBlock4);
    if (layout_ == BvhLayout::wide8 && options.node_pairing == NodePairing::automatic && !share &&
        least_block_bytes > l2_cache_bytes()) {
#pragma omp task default(shared)
        share = largest_box_area_share(prims.box_span(), kAutoMinLargestShare);
    }
    // The task reads prims and writes share: it ends before they go, also on an exception.
    struct EndOfTasks {
        ~EndOfTasks() {
#pragma omp taskwait
        }
    } const end_of_tasks;
    if (layout_ == BvhLayout::pairs) {
        pairs_ = make_bvh_pairs(bvh_);
        fill_slots(ids, scene.triangles);
    } else {
        wide8_ = make_bvh_wide<8>(bvh_, options.collapse);
        // The tree and the blocks are all the block layout keeps (plus others_).
        make_leaf_blocks(wide8_, ids, has_others, scene.triangles);
    }
#pragma omp taskwait  // the share's task
    if (!bvh_.empty()) bounds_ = bvh_.nodes[0].box();
    primitive_count_ = bvh_.prim_indices.size();
    unique_primitive_count_ = prims.size();
    if (layout_has_blocks(layout_) && !options.keep_binary_tree) bvh_ = Bvh{};
    if (layout_ == BvhLayout::wide8 && options.node_pairing != NodePairing::never) {
        if (options.node_pairing == NodePairing::always)
            pair_rays_ = PairRays::all;
        else if (bytes() > l2_cache_bytes() &&  // the interior test only where it matters
                 automatic_node_pairing(bytes(), l2_cache_bytes(),
                                        looks_like_interior(prims.size(), largest_share())))
            pair_rays_ = PairRays::inside;
    }
    if (layout_ == BvhLayout::wide8 && uses_tree_) choose_occlusion_order(options.occlusion_order);
}

/// The pairs layout's leaf data: slot s's vertices (zero for other kinds) and id.
void Accelerator::fill_slots(const SlotIds& ids, const TriangleSoup& soup) {
    const size_t slots = ids.size();
    slots_.resize(slots);
    // Tasks of the build's team (Accelerator::build); a thread that comes late takes a share.
#pragma omp taskloop default(shared) grainsize(kParallelLoopMin) if (int64_t(slots) > kParallelLoopMin)
    for (size_t s = 0; s < slots; ++s) {
        const uint32_t id = ids[s];
        slots_[s] =
            Slot{prim_kind(id) == PrimKind::triangle ? triangle_verts(soup, id) : TriangleVerts{}, id};
    }
}

namespace {

/// Occlusion rays that choose_occlusion_order traces: from the centroids of up to
/// `count` triangles spread over the leaf blocks, to either side, in directions from
/// a fixed hash (the same tree always gets the same order).
std::vector<Ray> occlusion_sample_rays(std::span<const TriangleBlock4> blocks, size_t count) {
    std::vector<Ray> rays;
    if (blocks.empty()) return rays;
    const size_t step = std::max<size_t>(1, blocks.size() / count);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    auto uniform = [&h]() {
        h ^= h >> 33, h *= 0xFF51AFD7ED558CCDull, h ^= h >> 33, h += 0x9E3779B97F4A7C15ull;
        return float(h >> 40) * 0x1p-24f;
    };
    for (size_t b = 0; b < blocks.size(); b += step) {
        const TriangleBlock4& blk = blocks[b];
        if ((blk.slot[0] & TriangleBlock4::kOtherKind) || blk.slot[0] == TriangleBlock4::kEmptyLane) continue;
        const Vec3 a(blk.p[0][0][0], blk.p[0][1][0], blk.p[0][2][0]);
        const Vec3 e1 = Vec3(blk.p[1][0][0], blk.p[1][1][0], blk.p[1][2][0]) - a;
        const Vec3 e2 = Vec3(blk.p[2][0][0], blk.p[2][1][0], blk.p[2][2][0]) - a;
        Vec3 n = normalize(cross(e1, e2));
        if (!is_finite(n)) continue;
        if (uniform() < 0.5f) n = -n;
        // A direction in the hemisphere of n: uniform on the sphere, flipped.
        const float z = 2.0f * uniform() - 1.0f, phi = 6.2831853f * uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        Vec3 d(r * std::cos(phi), r * std::sin(phi), z);
        if (dot(d, n) < 0.0f) d = -d;
        rays.push_back(Ray{offset_ray_origin(a + (e1 + e2) * (1.0f / 3.0f), n), d});
    }
    return rays;
}

}  // namespace

void Accelerator::choose_occlusion_order(OcclusionOrder order) {
    wide8_.occlusion_far_first = order == OcclusionOrder::far_first;
    if (order != OcclusionOrder::automatic) return;
    // Farthest first sorts the hit children, which slot order does not: it must save
    // enough nodes and leaf tests to pay for that (docs/performance.md, "Occlusion order").
    constexpr double kFarFirstMaxWork = 0.75;
    constexpr size_t kOcclusionSampleRays = 256;
    const std::vector<Ray> rays = occlusion_sample_rays(blocks_, kOcclusionSampleRays);
    uint64_t work[2] = {0, 0};
    for (int far = 0; far < 2; ++far) {
        wide8_.occlusion_far_first = far != 0;
        // Tasks of the build's team (Accelerator::build), a fixed split of the rays.
        constexpr size_t kTasks = 8;
        uint64_t part[kTasks] = {};
        for (size_t t = 0; t < kTasks; ++t) {
#pragma omp task default(shared) firstprivate(t)
            {
                TraversalCounters c;
                for (size_t i = rays.size() * t / kTasks; i < rays.size() * (t + 1) / kTasks; ++i)
                    occluded_counted(rays[i], c);
                part[t] = c.nodes_visited + c.prims_tested;
            }
        }
#pragma omp taskwait
        for (const uint64_t p : part) work[far] += p;
    }
    wide8_.occlusion_far_first = double(work[1]) < kFarFirstMaxWork * double(work[0]);
}

/// Rewrites every wide-tree leaf (first slot, count) to (first block, count), its
/// slots' triangles copied from the scene into blocks of four; lanes of other kinds and
/// padding get NaN vertices. The blocks are in node order, leaves numbered by a serial
/// prefix sum, filled by tasks (each block written once, by the thread that fills it).
template <int N>
void Accelerator::make_leaf_blocks(BvhWide<N>& tree, const SlotIds& ids, bool has_others,
                                   const TriangleSoup& soup) {
    size_t other_count = 0;
    const std::vector<uint32_t> other_rank = other_slot_ranks(ids, has_others, other_count);
    others_.assign(other_count, 0);
    constexpr float nan = std::numeric_limits<float>::quiet_NaN();
    auto fill_leaf = [&](uint32_t first, uint32_t count, uint32_t block) {
        for (uint32_t s = first; s < first + count; s += 4, ++block) {
            TriangleBlock4& b = blocks_[block];
            for (int l = 0; l < 4; ++l) {
                const uint32_t slot = s + uint32_t(l);
                const uint32_t id = slot < first + count ? ids[slot] : 0;
                const bool tri = slot < first + count && prim_kind(id) == PrimKind::triangle;
                if (slot >= first + count) {
                    b.slot[l] = TriangleBlock4::kEmptyLane;
                } else if (tri) {
                    b.slot[l] = id;
                } else {
                    b.slot[l] = other_rank[slot] | TriangleBlock4::kOtherKind;
                    others_[other_rank[slot]] = id;
                }
                const TriangleVerts t = tri ? triangle_verts(soup, id) : TriangleVerts{};
                for (int v = 0; v < 3; ++v)
                    for (int a = 0; a < 3; ++a) b.p[v][a][l] = tri ? t.p[v][a] : nan;
            }
        }
    };
    auto blocks_of = [](uint32_t count) { return (count + 3) / 4; };
    if (tree.empty) return;
    if (tree.root.is_leaf()) {
        const auto block = uint32_t(blocks_.size());
        blocks_.resize(block + blocks_of(tree.root.count));
        fill_leaf(tree.root.index, tree.root.count, block);
        tree.root.index = block;
        return;
    }
    const auto nodes = int64_t(tree.nodes.size());
    BuildArray<uint32_t> first_block(tree.nodes.size());
    auto total = uint32_t(blocks_.size());
    for (int64_t i = 0; i < nodes; ++i) {
        first_block[size_t(i)] = total;
        for (int c = 0; c < N; ++c) total += blocks_of(tree.nodes[size_t(i)].leaf_count(c));
    }
    blocks_.resize(total);
    // Tasks of the build's team (Accelerator::build), in small pieces: a thread that comes
    // late still takes a share.
#pragma omp taskloop default(shared) grainsize(kParallelLoopMin / (4 * N)) if (nodes > kParallelLoopMin / N)
    for (int64_t i = 0; i < nodes; ++i) {
        BvhWideNode<N>& n = tree.nodes[size_t(i)];
        uint32_t block = first_block[size_t(i)];
        for (int c = 0; c < N; ++c)
            if (const uint32_t count = n.leaf_count(c)) {
                fill_leaf(ref_first(n.child[c]), count, block);
                n.child[c] = wide_leaf_ref(block, count);
                block += blocks_of(count);
            }
    }
}

size_t Accelerator::bytes() const {
    const size_t other = spheres_.size() * sizeof(Sphere) + boxes_.size() * sizeof(Box) +
                         quadrics_.size() * sizeof(Quadric) + alpha_.bytes() + one_sided_.size();
    // The block layout keeps only the tree, the blocks (vertices and triangle ids) and the
    // ids of other kinds.
    if (layout_has_blocks(layout_))
        return wide8_.bytes() + blocks_.size() * sizeof(TriangleBlock4) + others_.size() * sizeof(uint32_t) +
               other;
    return pairs_.bytes() + bvh_.prim_indices.size() * sizeof(uint32_t) + slots_.size() * sizeof(Slot) +
           other;
}

// The kind tag picks the shape's own member (geometry/shape.h): a switch, no virtual
// call. Triangles are tested by the callers (blocks, slots); planes are never in the tree.
std::optional<ShapeHit> Accelerator::intersect_other(const Ray& ray, uint32_t id, float tmax) const {
    Ray r = ray;
    r.tmax = tmax;
    switch (prim_kind(id)) {
        case PrimKind::sphere:
            return spheres_[prim_index(id)].intersect(r);
        case PrimKind::box:
            return boxes_[prim_index(id)].intersect(r);
        case PrimKind::quadric:
            return quadrics_[prim_index(id)].intersect(r);
        default:
            return std::nullopt;
    }
}

bool Accelerator::occluded_other(const Ray& ray, uint32_t id, float tmax) const {
    Ray r = ray;
    r.tmax = tmax;
    switch (prim_kind(id)) {
        case PrimKind::sphere:
            return spheres_[prim_index(id)].occluded(r);
        case PrimKind::box:
            return boxes_[prim_index(id)].occluded(r);
        case PrimKind::quadric:
            return quadrics_[prim_index(id)].occluded(r);
        default:
            return false;
    }
}

template <bool kAnyHit, class Counters>
bool Accelerator::trace(Ray& ray, Hit& hit, Counters& counters) const {
    return alpha_.empty() ? trace_layout<kAnyHit, false>(ray, hit, counters)
                          : trace_layout<kAnyHit, true>(ray, hit, counters);
}

template <bool kAnyHit, bool kCutouts, class Counters>
bool Accelerator::trace_layout(Ray& ray, Hit& hit, Counters& counters) const {
    if (layout_ == BvhLayout::wide8) {
        // One traversal body compiled three times (SSE2, AVX2, AVX-512), each in its own
        // file (trace_wide.inl).
        const SimdPath path = active_simd_path();
        if (path == SimdPath::avx512) {
            // Closest-hit rays pair nodes until their first hit (traverse_wide) where
            // AcceleratorOptions::node_pairing says so; occlusion rays only on AVX2.
            if (!kAnyHit && pair_rays_ != PairRays::none &&
                (pair_rays_ == PairRays::all || bounds_.contains(ray.origin)))
                return trace_wide_avx512<kAnyHit, kCutouts, true>(ray, hit, counters);
            return trace_wide_avx512<kAnyHit, kCutouts, false>(ray, hit, counters);
        }
        if (path == SimdPath::avx2) {
            if (pair_rays_ != PairRays::none && (pair_rays_ == PairRays::all || bounds_.contains(ray.origin)))
                return trace_wide_avx2<kAnyHit, kCutouts, true>(ray, hit, counters);
            return trace_wide_avx2<kAnyHit, kCutouts, false>(ray, hit, counters);
        }
        return trace_wide_sse2<kAnyHit, kCutouts, false>(ray, hit, counters);
    }
    return trace_pairs<kAnyHit, kCutouts>(ray, hit, counters);
}

/// The binary tree in pair layout. Not inlined into trace_layout: its frame and
/// saved registers would otherwise be paid by every call of the wide layouts, which
/// trace_layout reaches by a tail call.
template <bool kAnyHit, bool kCutouts, class Counters>
__attribute__((noinline)) bool Accelerator::trace_pairs(Ray& ray, Hit& hit, Counters& counters) const {
    const TriangleRay tr(ray);
    BvhRay br(ray);
    Hit best;
    const bool found = traverse_bvh_pairs<kAnyHit>(
        pairs_, br,
        [&](uint32_t first, uint32_t count, float& tmax) {
            return test_slots<kAnyHit, kCutouts>(ray, tr, first, count, tmax, best);
        },
        counters);
    if (found && !kAnyHit) {
        hit = best;
        ray.tmax = best.t;
    }
    return found;
}

bool Accelerator::intersect(Ray& ray, Hit& hit) const {
    NoTraversalCounters none;
    return trace<false>(ray, hit, none);
}

bool Accelerator::occluded(const Ray& ray) const {
    NoTraversalCounters none;
    Hit h;
    // Any-hit traces only read the ray (only closest-hit ones write tmax back), so it
    // is not copied: reading a copy just made waits for its stores to be forwarded.
    return trace<true>(const_cast<Ray&>(ray), h, none);
}

bool Accelerator::occluded(const Ray& ray, OcclusionCache& cache) const {
    if (cache.owner == this && cache.block < blocks_.size()) {
        const TriangleRay tr(ray);  // as the any-hit traversal makes it: the same leaf test
        float tmax = ray.tmax;
        Hit h;
        if (alpha_.empty() ? test_blocks<true, false, false>(ray, tr, cache.block, 4, tmax, h)
                           : test_blocks<true, true, false>(ray, tr, cache.block, 4, tmax, h))
            return true;
    }
    NoTraversalCounters none;
    Hit h;
    if (!trace<true>(const_cast<Ray&>(ray), h, none)) return false;
    // The pairs layout leaves prim unset: nothing to remember.
    if (h.prim < blocks_.size()) cache = OcclusionCache{this, h.prim};
    return true;
}

bool Accelerator::intersect_counted(Ray& ray, Hit& hit, TraversalCounters& counters) const {
    return trace<false>(ray, hit, counters);
}

bool Accelerator::occluded_counted(const Ray& ray, TraversalCounters& counters) const {
    Hit h;
    return trace<true>(const_cast<Ray&>(ray), h, counters);  // read only, as in occluded()
}

/// The block layout's brute force: every lane of every block, triangles by the scalar test.
bool Accelerator::brute_force_blocks(const Ray& ray, const TriangleRay& tr, float& tmax, Hit& hit) const {
    bool found = false;
    for (const TriangleBlock4& b : blocks_)
        for (int l = 0; l < 4; ++l) {
            if (b.slot[l] == TriangleBlock4::kEmptyLane) continue;
            const uint32_t id = lane_prim(b.slot[l]);
            std::optional<ShapeHit> h;
            if (prim_kind(id) == PrimKind::triangle) {
                const TriangleVerts tri{{{b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]},
                                         {b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]},
                                         {b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]}}};
                h = tri.intersect(tr, ray.tmin, tmax);
                if (h && !one_sided_.empty() &&
                    culls(id, ray.dir, tri.vertex(0), tri.vertex(1), tri.vertex(2)))
                    h.reset();
                if (h && !alpha_.empty() && !keep_triangle_hit(ray, id, h->u, h->v)) h.reset();
            } else {
                h = intersect_other(ray, id, tmax);
            }
            if (!h) continue;
            tmax = h->t;
            hit = Hit{h->t, id, h->u, h->v};
            found = true;
        }
    return found;
}

/// Packet fallback for a non-triangle lane of a leaf block (packets run only on the block layout, without
/// cut-outs).
bool Accelerator::intersect_slot(const Ray& ray, uint32_t other, Hit& hit) const {
    const uint32_t id = others_[other];
    const std::optional<ShapeHit> h = intersect_other(ray, id, ray.tmax);
    if (!h) return false;
    hit = Hit{h->t, id, 0.0f, 0.0f};
    return true;
}

bool Accelerator::intersect_brute_force(Ray& ray, Hit& hit) const {
    const TriangleRay tr(ray);
    float tmax = ray.tmax;
    Hit best;
    const bool found = layout_has_blocks(layout_) ? brute_force_blocks(ray, tr, tmax, best)
                       : alpha_.empty()
                           ? test_slots<false, false>(ray, tr, 0, uint32_t(slots_.size()), tmax, best)
                           : test_slots<false, true>(ray, tr, 0, uint32_t(slots_.size()), tmax, best);
    if (!found) return false;
    hit = best;
    ray.tmax = best.t;
    return true;
}

}  // namespace sahara
