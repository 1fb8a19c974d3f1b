#pragma once
/// The acceleration structure over all bounded primitives of a Scene
/// (triangles, spheres, boxes); planes are unbounded and handled by Scene.
/// One binary SAH BVH holds every kind; a leaf dispatches on the kind stored
/// in the primitive id (geometry/hit.h) with a switch, never a virtual call.
/// The accelerator copies the primitive data it tests (triangle vertices in
/// leaf order, spheres, boxes), so it stays valid when the Scene is moved.
/// Scenes with cut-out triangles (scene/alpha_filter.h) run a second
/// instantiation of the traversal whose triangle hits pass the alpha test
/// before they count; the others run the traversal without it.
/// One-sided triangles (a material with double_sided false) are not cut-outs:
/// a hit on their back is dropped by a per-triangle flag at hit acceptance, in
/// every traversal (single rays and packets), so they keep the fast paths.
#include <algorithm>
#include <string_view>
#include <vector>

#include "scene/alpha_filter.h"
#include "accel/bvh.h"
#include "accel/traverse_wide.h"
#include "accel/bvh4_leaf.h"
#include "accel/bvh_pairs.h"
#include "accel/bvh_traverse.h"
#include "geometry/box.h"
#include "geometry/hit.h"
#include "geometry/quadric.h"
#include "geometry/sphere.h"
#include "geometry/triangle.h"
#include "math/bounds.h"

namespace sahara {

class Scene;
struct TriangleSoup;
struct SlotIds;
struct RayPacket;
struct HitPacket;
/// One instruction set's traversal entry point for one form (trace_wide.inl).
template <SimdPath kPath, class Form>
struct TraceWideEntry;

/// Largest primitive count for which the accelerator skips the SAH build and
/// tests everything in one root leaf (a flat loop). 0, no separate flat path: the
/// SAH already makes a root leaf when no split pays off, and from about 6 primitives
/// the tree is faster (`sahara bench --small-scenes` compares the two).
inline constexpr uint32_t kFlatLoopMaxPrims = 0;

/// When rays on a wide8 tree test the inner node on top of the stack together with the
/// one they visit (traverse_wide): closest-hit rays on the AVX-512 and AVX2 paths,
/// occlusion rays on the AVX2 path.
enum class NodePairing : uint8_t {
    /// wide8 trees larger than the L2 cache, for rays from inside the scene's bounds,
    /// except on interiors (looks_like_interior in accel/bvh.h)
    automatic,
    always,  ///< every ray that can pair, from anywhere, whatever the tree's size (tests)
    never,
};

/// NodePairing::automatic's rule: pair when the tree is larger than the L2 cache
/// (cache_bytes), except on interiors (looks_like_interior in accel/bvh.h). Their rays
/// mostly start in a room and hit within it: the stack entry a paired step tests
/// would mostly have been culled by that near hit, and the part of the tree they
/// touch stays cached.
bool automatic_node_pairing(size_t tree_bytes, size_t cache_bytes, bool interior);

/// In which order occlusion rays on a wide8 tree visit the children a node test hits
/// (BvhWide::occlusion_far_first).
enum class OcclusionOrder : uint8_t {
    automatic,  ///< farthest first when it saves work on sample rays (Accelerator::choose_occlusion_order)
    slot,       ///< slot order: no sorting, best where an occluder is as likely near as far
    far_first,  ///< farthest entry distance first: interiors, where the room's shell stops most rays
};

/// Build choices for an Accelerator.
struct AcceleratorOptions {
    /// wide8 by default: one AVX step tests eight children; pairs is the plain binary
    /// tree, the reference.
    BvhLayout layout = kDefaultBvhLayout;
    BvhBuilder builder = kDefaultBvhBuilder;
    /// Rays the caller expects to trace (0: unknown), for BvhBuilder::automatic.
    double expected_rays = 0;
    BvhBuildParams params;
    /// The wide8 layout builds with params.intersection_cost times this and counts
    /// leaves in whole blocks of four (BvhBuildParams::leaf_block_size): a block
    /// tests four triangles per SSE step, and counting whole blocks keeps the build from
    /// making 2- and 3-triangle leaves that are mostly padding lanes.
    /// 0.5: instructions per diffuse ray within 0.2% of 1.0 and 5-6% below 0.25, with
    /// the smaller tree of the two best. Blocks of eight (two per AVX step) took 7% more.
    float wide8_leaf_cost_scale = 0.5f;
    /// How the block layout collapses the binary tree into the wide one: subtrees of up
    /// to 8 primitives (two blocks, the fast leaf test's limit) may become one leaf, and
    /// a block test costs as much as a node visit (Embree's weights in its SAH report).
    /// Merging helps camera rays and costs the other ray sets nothing; block costs of 0.5
    /// or 0.7 (larger leaves) are no better.
    WideCollapse collapse{8, 1.0};
    /// Scenes with at most this many primitives skip the SAH build and test
    /// every primitive in one root leaf (see kFlatLoopMaxPrims); 0: always build.
    uint32_t flat_loop_max_prims = kFlatLoopMaxPrims;
    /// Node pairing pays only where node fetches miss the L2 cache, whose latency it
    /// overlaps; on trees that fit in L2 it gains nothing. Camera rays from outside the
    /// bounds usually hit in the first subtree they enter, so the paired node would never
    /// have been visited: automatic pairing leaves them out. Nor does it pair on
    /// interiors, whose rays mostly hit near their origin (see docs/performance.md,
    /// "Generated interiors").
    NodePairing node_pairing = NodePairing::automatic;
    OcclusionOrder occlusion_order = OcclusionOrder::automatic;
    /// Keep the binary tree after the block layout has collapsed it (bvh(), for
    /// `sahara bvh` statistics); otherwise its memory is released.
    bool keep_binary_tree = false;

    /// `params` as the chosen layout builds with: the block layout scales the
    /// intersection cost and counts leaves in blocks of four.
    BvhBuildParams build_params() const {
        BvhBuildParams p = params;
        // A wide BVH's leaf reference holds its count in kLeafCountBits.
        if (layout != BvhLayout::pairs) p.max_leaf_size = std::min(p.max_leaf_size, kMaxWideLeafCount);
        if (layout_has_blocks(layout)) {
            p.intersection_cost *= wide8_leaf_cost_scale;
            p.leaf_block_size = 4;  // a leaf block tests four triangles at once
        }
        return p;
    }
};

/// Throws InputError when a scene of `total` bounded primitives, `largest_kind` of
/// them of one kind, is beyond what the structures index: 29-bit primitive indices
/// per kind (geometry/hit.h) and, but for `pairs`, the wide tree's leaf references
/// (2^26 slots). The Accelerator checks before it builds anything.
void check_accelerator_capacity(size_t total, size_t largest_kind, BvhLayout layout);

/// Options for an Accelerator whose leaves feed the all-crossings queries
/// (accel/crossings.h): a builder that references every primitive exactly once.
inline AcceleratorOptions crossings_accelerator_options() {
    AcceleratorOptions o;
    o.builder = BvhBuilder::binned;
    return o;
}

class Accelerator {
   public:
    explicit Accelerator(const Scene& scene, const AcceleratorOptions& options = {});

    /// Nearest hit with t in (ray.tmin, ray.tmax); on a hit, ray.tmax becomes hit.t.
    bool intersect(Ray& ray, Hit& hit) const;
    /// Whether any primitive blocks the ray in (ray.tmin, ray.tmax).
    bool occluded(const Ray& ray) const;
    /// occluded() that tests `cache`'s block first and remembers the occluder there
    /// (one cache per light and thread; same answers as occluded()).
    bool occluded(const Ray& ray, OcclusionCache& cache) const;
    /// intersect() that also counts node visits and primitive tests into `counters`.
    bool intersect_counted(Ray& ray, Hit& hit, TraversalCounters& counters) const;
    /// occluded() that also counts node visits and primitive tests into `counters`.
    bool occluded_counted(const Ray& ray, TraversalCounters& counters) const;
    /// Nearest hits of the active rays of a packet (accel/packet.h); on a hit,
    /// the lane's tmax becomes hit.t. Per ray the answer is intersect()'s up to
    /// ties between primitives at exactly the same distance. The pairs layout,
    /// scenes with cut-outs and incoherent packets (mixed direction signs
    /// or dominant axes) are traced ray by ray.
    void intersect_packet(RayPacket& packet, HitPacket& hits) const;
    /// Tests the non-triangle primitive others_[other] of the block layout alone (packet
    /// fallback); on a hit with t in (ray.tmin, ray.tmax) fills `hit` and returns true.
    bool intersect_slot(const Ray& ray, uint32_t other, Hit& hit) const;
    /// The primitive id of a block lane (not padding).
    uint32_t lane_prim(uint32_t lane) const {
        return lane & TriangleBlock4::kOtherKind ? others_[lane & ~TriangleBlock4::kOtherKind] : lane;
    }
    /// Reference answer: tests every primitive, no tree (for tests).
    bool intersect_brute_force(Ray& ray, Hit& hit) const;

    Bounds3 bounds() const { return bounds_; }
    /// The binary tree; empty for the block layout unless AcceleratorOptions::keep_binary_tree.
    const Bvh& bvh() const { return bvh_; }
    /// False when the scene was small enough for the flat loop.
    bool uses_tree() const { return uses_tree_; }
    /// Whether rays pair nodes (NodePairing; with NodePairing::automatic only rays from
    /// inside bounds()). The SSE2 path never does.
    bool pairs_nodes() const { return pair_rays_ != PairRays::none; }
    /// Whether occlusion rays visit hit children farthest first (OcclusionOrder resolved).
    bool occlusion_far_first() const { return wide8_.occlusion_far_first; }
    BvhLayout layout() const { return layout_; }
    /// The 8-wide tree (empty unless the layout is wide8; a leaf's child index is its first block).
    const Bvh8& bvh8() const { return wide8_; }
    /// Leaf triangle blocks of the wide8 layout (empty for pairs).
    const auto& leaf_blocks() const { return blocks_; }
    /// Elapsed build time (BVH, pair layout, leaf-ordered primitive copies).
    double build_ms() const { return build_ms_; }
    /// CPU time of the build summed over threads (steadier than build_ms on shared cores).
    double build_cpu_ms() const { return build_cpu_ms_; }
    /// The builder that made the tree (BvhBuilder::automatic resolved).
    BvhBuilder builder() const { return builder_; }
    /// Primitives in the tree (each counted once, however many leaves reference it).
    size_t primitive_count() const { return unique_primitive_count_; }
    /// Leaf references: primitive_count() plus the duplicates of spatial splits.
    size_t reference_count() const { return primitive_count_; }
    /// Whether some primitive is referenced from several leaves (BvhBuilder::sbvh). The
    /// all-crossings queries (accel/crossings.h) would count such a primitive once per
    /// leaf the ray enters: they need a tree built with crossings_accelerator_options().
    bool has_split_references() const { return primitive_count_ > unique_primitive_count_; }
    /// Whether traversal runs the cut-out (alpha-tested) variant: the scene has
    /// triangles with a cut-out material (scene/alpha_filter.h).
    bool has_cutouts() const { return !alpha_.empty(); }
    /// The alpha test applied to cut-out triangle hits.
    const AlphaFilter& alpha_filter() const { return alpha_; }
    /// Triangles whose back faces rays pass through (one-sided materials).
    size_t one_sided_count() const { return one_sided_count_; }
    /// Bytes of the traversal tree plus the leaf-ordered primitive data it tests.
    size_t bytes() const;

   private:
    /// Picks the traversal instantiation: with the alpha test only for scenes with cut-outs.
    template <bool kAnyHit, class Counters>
    bool trace(Ray& ray, Hit& hit, Counters& counters) const;
    template <bool kAnyHit, bool kCutouts, class Counters>
    bool trace_layout(Ray& ray, Hit& hit, Counters& counters) const;
    template <bool kAnyHit, bool kCutouts, class Counters>
    bool trace_pairs(Ray& ray, Hit& hit, Counters& counters) const;
    /// The wide8 traversal (trace_wide.inl) and its entry point per instruction set, each
    /// compiled in its own file (trace_wide_sse2.cpp, trace_wide_avx2.cpp,
    /// trace_wide_avx512.cpp), which emits every form trace_layout calls (TraceForm).
    template <bool kAnyHit, bool kCutouts, bool kAvx, bool kAvx512, bool kPairNodes, class Counters>
    bool trace_wide_body(Ray& ray, Hit& hit, Counters& counters) const;
    template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
    bool trace_wide_sse2(Ray& ray, Hit& hit, Counters& counters) const;
    template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
    __attribute__((target("avx2"))) bool trace_wide_avx2(Ray& ray, Hit& hit, Counters& counters) const;
    template <bool kAnyHit, bool kCutouts, bool kPairNodes, class Counters>
    __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) bool trace_wide_avx512(
        Ray& ray, Hit& hit, Counters& counters) const;
    /// Names the entry points above for the files that emit them (trace_wide.inl).
    template <SimdPath, class>
    friend struct TraceWideEntry;
    /// Packets over the wide8 tree with the single-ray box and leaf tests (packet_wide8.cpp).
    __attribute__((target("avx2"))) void trace_packet8_avx2(const RayPacket& p, HitPacket& out) const;
    /// Any hit: hit.prim receives the block index of the occluder (OcclusionCache).
    template <bool kAnyHit, bool kCutouts, bool kAvx>
    bool test_blocks(const Ray& ray, const TriangleRay& tr, uint32_t first, uint32_t count, float& tmax,
                     Hit& hit) const;
    /// test_blocks for the traversal's call-free inner loop (LeafResult::slow: use test_blocks).
    template <bool kAnyHit, bool kCutouts, bool kAvx>
    LeafResult test_blocks_fast(const Ray& ray, const TriangleRay& tr, uint32_t first, uint32_t count,
                                uint32_t next_first, uint32_t next_count, bool& paired, float& tmax,
                                Hit& hit) const;
    /// Resolves OcclusionOrder::automatic: traces sample occlusion rays in both orders.
    void choose_occlusion_order(OcclusionOrder order);
    /// The constructor's work: build_stages in the build's thread team.
    void build(const Scene& scene, const AcceleratorOptions& options);
    /// Primitive boxes, tree, leaf data, node pairing and occlusion order.
    void build_stages(const Scene& scene, const AcceleratorOptions& options);
    void fill_slots(const SlotIds& ids, const TriangleSoup& soup);
    template <int N>
    void make_leaf_blocks(BvhWide<N>& tree, const SlotIds& ids, bool has_others, const TriangleSoup& soup);
    /// Sphere, box or quadric `id` over (ray.tmin, tmax): the shape's intersect() or occluded().
    std::optional<ShapeHit> intersect_other(const Ray& ray, uint32_t id, float tmax) const;
    bool occluded_other(const Ray& ray, uint32_t id, float tmax) const;
    bool brute_force_blocks(const Ray& ray, const TriangleRay& tr, float& tmax, Hit& hit) const;
    template <bool kAnyHit, bool kCutouts>
    bool test_slots(const Ray& ray, const TriangleRay& tr, uint32_t first, uint32_t count, float& tmax,
                    Hit& hit) const;
    /// The any-hit filter: whether a hit (barycentrics u, v) on triangle `id` is kept.
    bool keep_triangle_hit(const Ray& ray, uint32_t id, float u, float v) const {
        const uint32_t e = alpha_.entry_of(prim_index(id));
        return e == AlphaFilter::kOpaque || alpha_.passes(e, ray, id, u, v);
    }
    /// Whether triangle `id` is one-sided and `dir` meets its back (counter-clockwise
    /// is the front; edge-on counts as the back, as a ray grazing it sees no front).
    bool culls(uint32_t id, const Vec3& dir, const Vec3& a, const Vec3& b, const Vec3& c) const {
        return one_sided_[prim_index(id)] && dot(cross(b - a, c - a), dir) >= 0.0f;
    }
    /// The hit lanes `mask` of blocks b0 (lanes 0-3) and b1 (lanes 4-7) without the
    /// back faces of one-sided triangles (call only when the scene has any).
    int cull_block_lanes(const Ray& ray, const TriangleBlock4* b0, const TriangleBlock4* b1, int mask) const;
    /// Of the hit lanes `mask` of the triangle blocks from `first` (lane l: lane
    /// l & 3 of block first + l / 4), the one kept lane (the nearest kept one; for
    /// kAnyHit the first) as a mask, or 0 when every hit is cut out.
    template <bool kAnyHit>
    int keep_block_lanes(const Ray& ray, uint32_t first, int mask, const float* t, const float* u,
                         const float* v) const;
    /// Leaf slot of lane l of the blocks from `first`.
    uint32_t block_slot(uint32_t first, int l) const { return blocks_[first + uint32_t(l >> 2)].slot[l & 3]; }

    Bvh bvh_;         ///< the binary tree (see bvh())
    BvhPairs pairs_;  ///< the same tree in pair layout (layout_ == pairs)
    Bvh8 wide8_;      ///< the same tree collapsed to 8-wide nodes (wide8 layout)
    std::vector<TriangleBlock4, FillLaterAllocator<TriangleBlock4, 64>>
        blocks_;  ///< wide8 layout: each leaf's slots in blocks of four
    BvhLayout layout_ = kDefaultBvhLayout;
    /// Which closest-hit rays pair nodes (NodePairing resolved for this tree).
    enum class PairRays : uint8_t { none, inside, all };
    PairRays pair_rays_ = PairRays::none;
    /// What a leaf slot holds: the primitive id and, for triangles, the vertices
    /// (together, so a leaf's data is one contiguous read).
    struct Slot {
        TriangleVerts tri;  ///< 36 bytes; zero for other kinds
        uint32_t id;        ///< make_prim_id(kind, index); 4 bytes, total 40
    };
    std::vector<Slot> slots_;  ///< pairs layout, in leaf order: slot s holds primitive
                               ///< bvh_.prim_indices[s]
    /// wide8 layout: ids of the non-triangle lanes (a triangle lane holds its id itself).
    std::vector<uint32_t> others_;
    std::vector<Sphere> spheres_;    ///< copy of Scene::spheres (indexed by sphere index)
    std::vector<Box> boxes_;         ///< copy of Scene::boxes (indexed by box index)
    std::vector<Quadric> quadrics_;  ///< copy of Scene::quadrics (indexed by quadric index)
    AlphaFilter alpha_;              ///< cut-out triangles (empty: traversal without the alpha test)
    /// Per triangle (prim index): 1 for a one-sided one; empty when the scene has none,
    /// so the traversals test emptiness once per hit and pay nothing else.
    std::vector<uint8_t> one_sided_;
    size_t one_sided_count_ = 0;
    Bounds3 bounds_;
    bool uses_tree_ = false;
    size_t primitive_count_ = 0;
    size_t unique_primitive_count_ = 0;  ///< primitives given to the builder
    BvhBuilder builder_ = BvhBuilder::binned;
    double build_ms_ = 0;
    double build_cpu_ms_ = 0;
};

}  // namespace sahara
