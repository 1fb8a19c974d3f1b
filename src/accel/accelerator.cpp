#include "accel/accelerator.h"

#include <time.h>

#include <chrono>
#include <limits>

#include "accel/box_intersect.h"
#include "scene/scene.h"

namespace sahara {

namespace {

/// The builder's view of the scene: one box, one centre and one id per primitive.
struct PrimitiveList {
    std::vector<Bounds3> boxes;
    std::vector<Vec3> centers;
    std::vector<uint32_t> ids;

    void add(const Bounds3& b, uint32_t id) {
        // A primitive with non-finite coordinates can never be hit; give it an
        // empty box (ignored by node bounds) and a harmless centre.
        const bool finite = is_finite(b.lo) && is_finite(b.hi);
        boxes.push_back(finite ? b : Bounds3{});
        centers.push_back(finite ? b.center() : Vec3(0.0f));
        ids.push_back(id);
    }
};

PrimitiveList collect_primitives(const Scene& scene) {
    PrimitiveList list;
    const TriangleSoup& soup = scene.triangles;
    const size_t n = soup.size() + scene.spheres.size() + scene.boxes.size() + scene.quadrics.size();
    list.boxes.reserve(n);
    list.centers.reserve(n);
    list.ids.reserve(n);
    for (uint32_t i = 0; i < soup.size(); ++i) {
        Bounds3 b;
        for (int k = 0; k < 3; ++k) b.extend(soup.positions[soup.indices[3 * i + k]]);
        list.add(b, make_prim_id(PrimKind::triangle, i));
    }
    for (uint32_t i = 0; i < scene.spheres.size(); ++i)
        list.add(scene.spheres[i].bounds(scene.camera.shutter_open, scene.camera.shutter_close),
                 make_prim_id(PrimKind::sphere, i));
    for (uint32_t i = 0; i < scene.boxes.size(); ++i)
        list.add(scene.boxes[i].box, make_prim_id(PrimKind::box, i));
    for (uint32_t i = 0; i < scene.quadrics.size(); ++i)
        list.add(scene.quadrics[i].bounds(), make_prim_id(PrimKind::quadric, i));
    return list;
}

double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

/// The flat loop: one root leaf over every primitive.
Bvh single_leaf_bvh(const PrimitiveList& prims) {
    Bvh bvh;
    const auto n = uint32_t(prims.ids.size());
    if (n == 0) return bvh;
    Bounds3 all;
    for (const Bounds3& b : prims.boxes) all.extend(b);
    BvhNode root{};
    root.set_box(all);
    root.index = 0;
    root.count = n;
    bvh.nodes.push_back(root);
    for (uint32_t i = 0; i < n; ++i) bvh.prim_indices.push_back(i);
    return bvh;
}

}  // namespace

const char* bvh_layout_name(BvhLayout layout) {
    return layout == BvhLayout::pairs ? "pairs" : layout == BvhLayout::wide4_slots ? "wide4-slots" : "wide4";
}

bool parse_bvh_layout(std::string_view text, BvhLayout& out) {
    if (text == "wide4")
        out = BvhLayout::wide4;
    else if (text == "wide4-slots")
        out = BvhLayout::wide4_slots;
    else if (text == "pairs")
        out = BvhLayout::pairs;
    else
        return false;
    return true;
}

Accelerator::Accelerator(const Scene& scene, const AcceleratorOptions& options)
    : spheres_(scene.spheres), quadrics_(scene.quadrics), alpha_(scene) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = process_cpu_ms();
    for (const Box& b : scene.boxes) boxes_.push_back(b.box);
    const PrimitiveList prims = collect_primitives(scene);
    uses_tree_ = prims.ids.size() > options.flat_loop_max_prims;
    BvhBuildParams params = options.params;
    if (options.layout == BvhLayout::wide4) {
        params.intersection_cost *= options.wide4_leaf_cost_scale;
        params.leaf_block_size = 4;  // a leaf block tests four triangles at once
    }
    bvh_ = uses_tree_ ? build_bvh({prims.boxes, prims.centers}, options.builder, params)
                      : single_leaf_bvh(prims);
    // Leaf-ordered primitive data: slot s holds primitive bvh_.prim_indices[s].
    const size_t slots = bvh_.prim_indices.size();
    std::vector<uint32_t> ids(slots);
    std::vector<TriangleVerts> tris(slots);
    const TriangleSoup& soup = scene.triangles;
    for (size_t s = 0; s < slots; ++s) {
        ids[s] = prims.ids[bvh_.prim_indices[s]];
        tris[s] = TriangleVerts{};
        if (prim_kind(ids[s]) == PrimKind::triangle) {
            const uint32_t* v = &soup.indices[3 * size_t(prim_index(ids[s]))];
            tris[s] = TriangleVerts::of(soup.positions[v[0]], soup.positions[v[1]], soup.positions[v[2]]);
        }
    }
    layout_ = options.layout;
    if (layout_ == BvhLayout::pairs)
        pairs_ = make_bvh_pairs(bvh_);
    else
        wide_ = make_bvh4(bvh_);
    if (layout_ == BvhLayout::wide4) {
        make_leaf_blocks(ids, tris);  // the blocks and ids_ are all the wide4 layout keeps
        ids_ = std::move(ids);
    } else {
        slots_.resize(slots);
        for (size_t s = 0; s < slots; ++s) slots_[s] = Slot{tris[s], ids[s]};
    }
    if (!bvh_.empty()) bounds_ = bvh_.nodes[0].box();
    build_cpu_ms_ = process_cpu_ms() - cpu_start;
    build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// Rewrites every BVH4 leaf (first slot, count) to (first block, count), its
/// slots copied into blocks of four; lanes of other kinds and padding get NaN vertices.
void Accelerator::make_leaf_blocks(const std::vector<uint32_t>& ids, const std::vector<TriangleVerts>& tris) {
    auto add_leaf = [&](uint32_t first, uint32_t count) {
        const auto block = uint32_t(blocks_.size());
        for (uint32_t s = first; s < first + count; s += 4) {
            TriangleBlock4 b{};
            for (int l = 0; l < 4; ++l) {
                const uint32_t slot = s + uint32_t(l);
                const bool in_leaf = slot < first + count;
                const bool tri = in_leaf && prim_kind(ids[slot]) == PrimKind::triangle;
                b.slot[l] = !in_leaf ? TriangleBlock4::kEmptyLane
                            : tri    ? slot
                                     : slot | TriangleBlock4::kOtherKind;
                for (int v = 0; v < 3; ++v)
                    for (int a = 0; a < 3; ++a)
                        b.p[v][a][l] = tri ? tris[slot].p[v][a] : std::numeric_limits<float>::quiet_NaN();
            }
            blocks_.push_back(b);
        }
        return block;
    };
    if (wide_.empty) return;
    if (wide_.root.is_leaf()) wide_.root.index = add_leaf(wide_.root.index, wide_.root.count);
    for (Bvh4Node& n : wide_.nodes)
        for (int c = 0; c < 4; ++c)
            if (n.count[c]) n.child[c] = add_leaf(n.child[c], n.count[c]);
}

size_t Accelerator::bytes() const {
    const size_t other = spheres_.size() * sizeof(Sphere) + boxes_.size() * sizeof(Bounds3) +
                         quadrics_.size() * sizeof(Quadric) + alpha_.bytes();
    // The wide4 layout keeps only the blocks (vertices) and one id per slot.
    if (layout_ == BvhLayout::wide4)
        return wide_.bytes() + blocks_.size() * sizeof(TriangleBlock4) + ids_.size() * sizeof(uint32_t) +
               other;
    return (layout_ == BvhLayout::pairs ? pairs_.bytes() : wide_.bytes()) +
           bvh_.prim_indices.size() * sizeof(uint32_t) + slots_.size() * sizeof(Slot) + other;
}

/// Tests sphere, box or quadric `id` for a hit in (ray.tmin, tmax); sets its t and u.
bool Accelerator::intersect_other(const Ray& ray, uint32_t id, float tmax, float& t, float& u) const {
    switch (prim_kind(id)) {
        case PrimKind::sphere: {
            const Sphere& sp = spheres_[prim_index(id)];
            Ray r = ray;
            r.tmax = tmax;
            const double ts = intersect_sphere(r, sp.center_at(ray.time), sp.radius);
            if (ts < 0.0) return false;
            t = float(ts);
            return true;
        }
        case PrimKind::box:
            return intersect_box(ray, boxes_[prim_index(id)], ray.tmin, tmax, t);
        case PrimKind::quadric: {
            Ray r = ray;
            r.tmax = tmax;
            const QuadricHit qh = quadrics_[prim_index(id)].intersect(r);
            if (!qh.hit()) return false;
            t = qh.t;
            u = float(int(qh.part));  // Scene::interact reads the part back from hit.u
            return true;
        }
        default:
            return false;  // triangles are tested by the caller; planes are never in the tree
    }
}

/// Tests the primitives in slots [first, first + count); the closest hit lowers `tmax` and is stored in
/// `hit`.
template <bool kAnyHit, bool kCutouts>
__attribute__((always_inline)) inline bool Accelerator::test_slots(const Ray& ray, const TriangleRay& tr,
                                                                   uint32_t first, uint32_t count,
                                                                   float& tmax, Hit& hit) const {
    bool found = false;
    for (uint32_t s = first; s < first + count; ++s) {
        const uint32_t id = slots_[s].id;
        float t = 0.0f, u = 0.0f, v = 0.0f;
        switch (prim_kind(id)) {
            case PrimKind::triangle: {
                TriangleHit th;
                if (!intersect_triangle(tr, slots_[s].tri, ray.tmin, tmax, th)) continue;
                if constexpr (kCutouts)
                    if (!keep_triangle_hit(ray, id, th.u, th.v)) continue;
                t = th.t, u = th.u, v = th.v;
                break;
            }
            default:
                if (!intersect_other(ray, id, tmax, t, u)) continue;
                break;
        }
        if constexpr (kAnyHit) return true;
        tmax = t;
        hit = Hit{t, id, u, v};
        found = true;
    }
    return found;
}

/// The BVH4 traversal; trace_wide_avx2 is the same code compiled for AVX2
/// (both inline this body, so each gets its own instruction selection).
template <bool kAnyHit, bool kCutouts, bool kBlocks, class Counters>
__attribute__((always_inline)) inline bool Accelerator::trace_wide_body(Ray& ray, Hit& hit,
                                                                        Counters& counters) const {
    const TriangleRay tr(ray);
    BvhRay br(ray);
    Hit best;
    const bool found = traverse_bvh4<kAnyHit>(
        wide_, br,
        [&](uint32_t first, uint32_t count, float& tmax) {
            if constexpr (kBlocks)
                return test_blocks<kAnyHit, kCutouts>(ray, tr, first, count, tmax, best);
            else
                return test_slots<kAnyHit, kCutouts>(ray, tr, first, count, tmax, best);
        },
        counters);
    if (found && !kAnyHit) {
        hit = best;
        ray.tmax = best.t;
    }
    return found;
}

template <bool kAnyHit, bool kCutouts, bool kBlocks, class Counters>
bool Accelerator::trace_wide(Ray& ray, Hit& hit, Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, kBlocks>(ray, hit, counters);
}

template <bool kAnyHit, bool kCutouts, bool kBlocks, class Counters>
__attribute__((target("avx2"))) bool Accelerator::trace_wide_avx2(Ray& ray, Hit& hit,
                                                                  Counters& counters) const {
    return trace_wide_body<kAnyHit, kCutouts, kBlocks>(ray, hit, counters);
}

template <bool kAnyHit>
__attribute__((always_inline)) inline int Accelerator::keep_block_lanes(const Ray& ray,
                                                                        const TriangleBlock4& block, int mask,
                                                                        const float t[4], const float u[4],
                                                                        const float v[4]) const {
    // Nearest first, so at most the lanes in front of the kept one are alpha-tested.
    while (mask) {
        int best = __builtin_ctz(unsigned(mask));
        if constexpr (!kAnyHit)
            for (int m = mask & (mask - 1); m; m &= m - 1) {
                const int l = __builtin_ctz(unsigned(m));
                if (t[l] < t[best]) best = l;
            }
        if (keep_triangle_hit(ray, ids_[block.slot[best]], u[best], v[best])) return 1 << best;
        mask &= ~(1 << best);
    }
    return 0;
}

/// Tests the leaf blocks [first, first + ceil(count / 4)): triangles four at a
/// time, other kinds through intersect_other; the closest hit lowers `tmax`.
template <bool kAnyHit, bool kCutouts>
__attribute__((always_inline)) inline bool Accelerator::test_blocks(const Ray& ray, const TriangleRay& tr,
                                                                    uint32_t first, uint32_t count,
                                                                    float& tmax, Hit& hit) const {
    bool found = false;
    for (uint32_t b = first; b < first + (count + 3) / 4; ++b) {
        const TriangleBlock4& block = blocks_[b];
        float t[4], u[4], v[4];
        // Sign bits of the slots: lanes of other kinds and padding. A block with
        // no triangle lane (e.g. a leaf of spheres) skips the triangle test.
        const int other =
            _mm_movemask_ps(_mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(block.slot))));
        int mask = other == 0xF ? 0 : intersect_triangle_block4(tr, block, ray.tmin, tmax, t, u, v);
        if constexpr (kCutouts)
            if (mask) mask = keep_block_lanes<kAnyHit>(ray, block, mask, t, u, v);
        if (mask) {
            if constexpr (kAnyHit) return true;
            int best = __builtin_ctz(unsigned(mask));
            for (int m = mask & (mask - 1); m; m &= m - 1) {
                const int l = __builtin_ctz(unsigned(m));
                if (t[l] < t[best]) best = l;
            }
            tmax = t[best];
            hit = Hit{t[best], ids_[block.slot[best]], u[best], v[best]};
            found = true;
        }
        for (int m = other; m; m &= m - 1) {
            const uint32_t slot = block.slot[__builtin_ctz(unsigned(m))];
            if (slot == TriangleBlock4::kEmptyLane) continue;
            const uint32_t id = ids_[slot & ~TriangleBlock4::kOtherKind];
            float t_other = 0.0f, u_other = 0.0f;
            if (!intersect_other(ray, id, tmax, t_other, u_other)) continue;
            if constexpr (kAnyHit) return true;
            tmax = t_other;
            hit = Hit{t_other, id, u_other, 0.0f};
            found = true;
        }
    }
    return found;
}

template <bool kAnyHit, class Counters>
bool Accelerator::trace(Ray& ray, Hit& hit, Counters& counters) const {
    return alpha_.empty() ? trace_layout<kAnyHit, false>(ray, hit, counters)
                          : trace_layout<kAnyHit, true>(ray, hit, counters);
}

template <bool kAnyHit, bool kCutouts, class Counters>
bool Accelerator::trace_layout(Ray& ray, Hit& hit, Counters& counters) const {
    const bool avx2 = active_simd_path() == SimdPath::avx2;
    if (layout_ == BvhLayout::wide4)
        return avx2 ? trace_wide_avx2<kAnyHit, kCutouts, true>(ray, hit, counters)
                    : trace_wide<kAnyHit, kCutouts, true>(ray, hit, counters);
    if (layout_ == BvhLayout::wide4_slots)
        return avx2 ? trace_wide_avx2<kAnyHit, kCutouts, false>(ray, hit, counters)
                    : trace_wide<kAnyHit, kCutouts, false>(ray, hit, counters);
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
    Ray r = ray;
    Hit h;
    return trace<true>(r, h, none);
}

bool Accelerator::intersect_counted(Ray& ray, Hit& hit, TraversalCounters& counters) const {
    return trace<false>(ray, hit, counters);
}

bool Accelerator::occluded_counted(const Ray& ray, TraversalCounters& counters) const {
    Ray r = ray;
    Hit h;
    return trace<true>(r, h, counters);
}

/// The wide4 brute force: every lane of every block, triangles by the scalar test.
bool Accelerator::brute_force_blocks(const Ray& ray, const TriangleRay& tr, float& tmax, Hit& hit) const {
    bool found = false;
    for (const TriangleBlock4& b : blocks_)
        for (int l = 0; l < 4; ++l) {
            if (b.slot[l] == TriangleBlock4::kEmptyLane) continue;
            const uint32_t id = ids_[b.slot[l] & ~TriangleBlock4::kOtherKind];
            float t = 0.0f, u = 0.0f, v = 0.0f;
            if (prim_kind(id) == PrimKind::triangle) {
                const TriangleVerts tri{{{b.p[0][0][l], b.p[0][1][l], b.p[0][2][l]},
                                         {b.p[1][0][l], b.p[1][1][l], b.p[1][2][l]},
                                         {b.p[2][0][l], b.p[2][1][l], b.p[2][2][l]}}};
                TriangleHit th;
                if (!intersect_triangle(tr, tri, ray.tmin, tmax, th)) continue;
                if (!alpha_.empty() && !keep_triangle_hit(ray, id, th.u, th.v)) continue;
                t = th.t, u = th.u, v = th.v;
            } else if (!intersect_other(ray, id, tmax, t, u)) {
                continue;
            }
            tmax = t;
            hit = Hit{t, id, u, v};
            found = true;
        }
    return found;
}

/// Packet fallback for a non-triangle lane of a wide4 leaf block (packets run only on wide4, without
/// cut-outs).
bool Accelerator::intersect_slot(const Ray& ray, uint32_t slot, Hit& hit) const {
    const uint32_t id = ids_[slot];
    float t = 0.0f, u = 0.0f;
    if (!intersect_other(ray, id, ray.tmax, t, u)) return false;
    hit = Hit{t, id, u, 0.0f};
    return true;
}

bool Accelerator::intersect_brute_force(Ray& ray, Hit& hit) const {
    const TriangleRay tr(ray);
    float tmax = ray.tmax;
    Hit best;
    const bool found = layout_ == BvhLayout::wide4 ? brute_force_blocks(ray, tr, tmax, best)
                       : alpha_.empty()
                           ? test_slots<false, false>(ray, tr, 0, uint32_t(slots_.size()), tmax, best)
                           : test_slots<false, true>(ray, tr, 0, uint32_t(slots_.size()), tmax, best);
    if (!found) return false;
    hit = best;
    ray.tmax = best.t;
    return true;
}

}  // namespace sahara
