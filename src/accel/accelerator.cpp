#include "accel/accelerator.h"

#include <time.h>

#include <chrono>

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
    for (uint32_t i = 0; i < scene.boxes.size(); ++i) list.add(scene.boxes[i].box, make_prim_id(PrimKind::box, i));
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

Accelerator::Accelerator(const Scene& scene, const AcceleratorOptions& options)
    : spheres_(scene.spheres), quadrics_(scene.quadrics) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = process_cpu_ms();
    for (const Box& b : scene.boxes) boxes_.push_back(b.box);
    const PrimitiveList prims = collect_primitives(scene);
    uses_tree_ = prims.ids.size() > options.flat_loop_max_prims;
    bvh_ = uses_tree_ ? build_bvh({prims.boxes, prims.centers}, options.builder, options.params)
                      : single_leaf_bvh(prims);
    // Leaf-ordered primitive data: slot s holds primitive bvh_.prim_indices[s].
    const size_t slots = bvh_.prim_indices.size();
    slots_.resize(slots);
    const TriangleSoup& soup = scene.triangles;
    for (size_t s = 0; s < slots; ++s) {
        const uint32_t id = prims.ids[bvh_.prim_indices[s]];
        slots_[s].id = id;
        slots_[s].tri = TriangleVerts{};
        if (prim_kind(id) == PrimKind::triangle) {
            const uint32_t* v = &soup.indices[3 * size_t(prim_index(id))];
            slots_[s].tri = TriangleVerts::of(soup.positions[v[0]], soup.positions[v[1]], soup.positions[v[2]]);
        }
    }
    pairs_ = make_bvh_pairs(bvh_);
    if (!bvh_.empty()) bounds_ = bvh_.nodes[0].box();
    build_cpu_ms_ = process_cpu_ms() - cpu_start;
    build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

size_t Accelerator::bytes() const {
    return pairs_.bytes() + bvh_.prim_indices.size() * sizeof(uint32_t) + slots_.size() * sizeof(Slot) +
           spheres_.size() * sizeof(Sphere) + boxes_.size() * sizeof(Bounds3) + quadrics_.size() * sizeof(Quadric);
}

/// Tests the primitives in slots [first, first + count); the closest hit lowers `tmax` and is stored in `hit`.
template <bool kAnyHit>
__attribute__((always_inline)) inline bool Accelerator::test_slots(const Ray& ray, const TriangleRay& tr, uint32_t first, uint32_t count, float& tmax,
                             Hit& hit) const {
    bool found = false;
    for (uint32_t s = first; s < first + count; ++s) {
        const uint32_t id = slots_[s].id;
        float t = 0.0f, u = 0.0f, v = 0.0f;
        switch (prim_kind(id)) {
            case PrimKind::triangle: {
                TriangleHit th;
                if (!intersect_triangle(tr, slots_[s].tri, ray.tmin, tmax, th)) continue;
                t = th.t, u = th.u, v = th.v;
                break;
            }
            case PrimKind::sphere: {
                const Sphere& sp = spheres_[prim_index(id)];
                Ray r = ray;
                r.tmax = tmax;
                const double ts = intersect_sphere(r, sp.center_at(ray.time), sp.radius);
                if (ts < 0.0) continue;
                t = float(ts);
                break;
            }
            case PrimKind::box:
                if (!intersect_box(ray, boxes_[prim_index(id)], ray.tmin, tmax, t)) continue;
                break;
            case PrimKind::quadric: {
                Ray r = ray;
                r.tmax = tmax;
                const QuadricHit qh = quadrics_[prim_index(id)].intersect(r);
                if (!qh.hit()) continue;
                t = qh.t;
                u = float(int(qh.part));  // Scene::interact reads the part back from hit.u
                break;
            }
            case PrimKind::plane:
                continue;  // unbounded: never in the tree
        }
        if constexpr (kAnyHit) return true;
        tmax = t;
        hit = Hit{t, id, u, v};
        found = true;
    }
    return found;
}

template <bool kAnyHit, class Counters>
bool Accelerator::trace(Ray& ray, Hit& hit, Counters& counters) const {
    const TriangleRay tr(ray);
    BvhRay br(ray);
    Hit best;
    const bool found = traverse_bvh_pairs<kAnyHit>(
        pairs_, br,
        [&](uint32_t first, uint32_t count, float& tmax) {
            return test_slots<kAnyHit>(ray, tr, first, count, tmax, best);
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

bool Accelerator::intersect_brute_force(Ray& ray, Hit& hit) const {
    const TriangleRay tr(ray);
    float tmax = ray.tmax;
    Hit best;
    if (!test_slots<false>(ray, tr, 0, uint32_t(slots_.size()), tmax, best)) return false;
    hit = best;
    ray.tmax = best.t;
    return true;
}

}  // namespace sahara
