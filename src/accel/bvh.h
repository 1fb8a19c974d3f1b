#pragma once
/// A binary bounding volume hierarchy as pure data, plus its builders. The
/// builders see only one bounding box and one centre per primitive, never a
/// triangle or a sphere; traversal (accel/bvh_traverse.h) hands leaf ranges to
/// a caller-supplied functor, so the caller owns the primitive tests.
///
/// Layout: 32-byte nodes in 64-byte aligned storage, the two children of an
/// inner node adjacent (nodes[i], nodes[i + 1], i even, so a sibling pair is
/// one cache line), root at nodes[0], nodes[1] unused padding. A leaf's
/// primitives are the slots prim_indices[index .. index + count).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <span>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "base/bvh_choice.h"
#include "math/bounds.h"

namespace sahara {

/// One node: 24 bytes of bounds + 8 bytes of links = 32 bytes (two per 64-byte cache line).
struct BvhNode {
    /// lo.x, hi.x, lo.y, hi.y, lo.z, hi.z: interleaved so the near plane of
    /// an axis is bounds[2 * axis + (direction < 0)] and the far plane the other one.
    float bounds[6];
    uint32_t index;  ///< inner: first child (the second is index + 1); leaf: first primitive slot
    uint32_t count;  ///< number of primitives; 0 marks an inner node

    bool is_leaf() const { return count != 0; }
    Bounds3 box() const { return {{bounds[0], bounds[2], bounds[4]}, {bounds[1], bounds[3], bounds[5]}}; }
    void set_box(const Bounds3& b) {
        bounds[0] = b.lo.x;
        bounds[1] = b.hi.x;
        bounds[2] = b.lo.y;
        bounds[3] = b.hi.y;
        bounds[4] = b.lo.z;
        bounds[5] = b.hi.z;
    }
};
static_assert(sizeof(BvhNode) == 32, "two nodes per cache line");

/// Arrays of at least kHugePageMinBytes are 2 MiB aligned, rounded up to whole 2 MiB
/// pages and marked for transparent huge pages: traversal jumps across node and leaf
/// arrays of several MiB, and with 4 KiB pages nearly every node visit also misses the
/// TLB; and a fresh array on 4 KiB pages costs a page fault every 4 KiB as it is
/// written, a large share of an acceleration build (clearing the unused end of the
/// last huge page costs less).
inline constexpr size_t kHugePageBytes = size_t(2) << 20;
inline constexpr size_t kHugePageMinBytes = size_t(1) << 20;
/// Marks [p, p + bytes) for transparent huge pages (a hint; no effect where unsupported).
void advise_huge_pages(void* p, size_t bytes);

/// While one of these is alive, the huge-page blocks AlignedAllocator frees are kept and
/// handed to later requests they fit, instead of going back to the system; they are freed
/// when the last scope ends. A fresh block costs the kernel's zeroing of each page at its
/// first touch, and each phase of an acceleration build (binary tree, collapse, leaf
/// blocks) would otherwise pay it again for memory the phase before had just freed.
class HugeBlockReuse {
   public:
    HugeBlockReuse();
    ~HugeBlockReuse();
    HugeBlockReuse(const HugeBlockReuse&) = delete;
    HugeBlockReuse& operator=(const HugeBlockReuse&) = delete;
};
/// A kept block of at least `bytes` (whole huge pages), or nullptr.
void* take_kept_huge_block(size_t bytes);
/// Keeps block `p` of `bytes` if a HugeBlockReuse is alive; false: the caller frees it.
bool keep_huge_block(void* p, size_t bytes);

/// Minimal allocator returning `Align`-byte aligned storage (huge pages for big arrays).
template <class T, size_t Align>
struct AlignedAllocator {
    using value_type = T;
    template <class U>
    struct rebind {
        using other = AlignedAllocator<U, Align>;
    };
    AlignedAllocator() = default;
    template <class U>
    AlignedAllocator(const AlignedAllocator<U, Align>&) {}
    static constexpr size_t alignment(size_t bytes) {
        return bytes >= kHugePageMinBytes && Align < kHugePageBytes ? kHugePageBytes : Align;
    }
    /// Bytes actually reserved for `bytes`: whole huge pages when huge-page aligned.
    static constexpr size_t reserved(size_t bytes) {
        return alignment(bytes) == kHugePageBytes
                   ? (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes
                   : bytes;
    }
    T* allocate(size_t n) {
        if (n > std::numeric_limits<size_t>::max() / 4 / sizeof(T)) throw std::bad_array_new_length();
        const size_t bytes = n * sizeof(T);
        const bool huge = alignment(bytes) == kHugePageBytes;
        if (huge)
            if (void* kept = take_kept_huge_block(reserved(bytes))) return static_cast<T*>(kept);
        void* p = ::operator new(reserved(bytes), std::align_val_t(alignment(bytes)));
        if (huge) advise_huge_pages(p, reserved(bytes));
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t n) {
        const size_t bytes = n * sizeof(T);
        if (alignment(bytes) == kHugePageBytes && keep_huge_block(p, reserved(bytes))) return;
        ::operator delete(p, std::align_val_t(alignment(bytes)));
    }
    friend bool operator==(const AlignedAllocator&, const AlignedAllocator&) { return true; }
};

/// AlignedAllocator whose resize() default-initialises (leaves trivial elements
/// unwritten): for arrays that are filled right after they are sized, where value
/// initialisation would write every byte twice.
template <class T, size_t Align>
struct FillLaterAllocator : AlignedAllocator<T, Align> {
    template <class U>
    struct rebind {
        using other = FillLaterAllocator<U, Align>;
    };
    FillLaterAllocator() = default;
    template <class U>
    FillLaterAllocator(const FillLaterAllocator<U, Align>&) {}
    template <class U>
    void construct(U* p) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// Uninitialised build scratch of `n` trivially copyable T (aligned and on huge pages
/// like AlignedAllocator's arrays): the builders' big temporaries are written before
/// they are read, so zero-filling them (std::vector) would write every byte twice.
template <class T>
class BuildArray {
   public:
    BuildArray() = default;
    explicit BuildArray(size_t n) : p_(n ? Alloc().allocate(n) : nullptr), n_(n) {}
    BuildArray(BuildArray&& o) noexcept : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)) {}
    BuildArray& operator=(BuildArray&& o) noexcept {
        std::swap(p_, o.p_);
        std::swap(n_, o.n_);
        return *this;
    }
    ~BuildArray() {
        if (p_) Alloc().deallocate(p_, n_);
    }
    T* get() const { return p_; }
    T& operator[](size_t i) const { return p_[i]; }
    size_t size() const { return n_; }

   private:
    static_assert(std::is_trivially_copyable_v<T>);
    using Alloc = AlignedAllocator<T, 64>;
    T* p_ = nullptr;
    size_t n_ = 0;
};

/// The hierarchy. An empty Bvh (no nodes) has no primitives.
struct Bvh {
    /// Index of the first sibling pair (nodes[1] is padding).
    static constexpr uint32_t kFirstPair = 2;
    /// Not zero-filled when resized: every builder writes each node it keeps.
    std::vector<BvhNode, FillLaterAllocator<BvhNode, 64>> nodes;
    std::vector<uint32_t> prim_indices;  ///< leaf slot -> index of the primitive given to the builder

    bool empty() const { return nodes.empty(); }
    /// Bytes of nodes (padding included) and slot indices (what traversal reads besides primitive data).
    size_t bytes() const { return nodes.size() * sizeof(BvhNode) + prim_indices.size() * sizeof(uint32_t); }
};

/// SAH cost model and build limits. The costs are relative: visiting an inner
/// node (two box tests) costs `traversal`, testing one primitive costs
/// `intersection`. A node becomes a leaf when that is cheaper than its best split.
struct BvhBuildParams {
    float traversal_cost = 1.0f;
    float intersection_cost = 1.0f;
    uint32_t max_leaf_size = 16;  ///< larger ranges are always split
    /// Leaves are tested in blocks of this many primitives (a partly filled block
    /// costs as much as a full one), so the SAH counts ceil(n / size) * size.
    uint32_t leaf_block_size = 1;
    uint32_t bin_count = 16;  ///< binned builder: centroid bins per axis (at most 8 for ranges of up to 64)
    /// Binned builder: ranges of at most this many primitives (at most 16) are split by an
    /// exact SAH sweep over their centroid orders instead of bins (a better split for
    /// the same work; longer ranges cost more swept than binned); 0: bins everywhere.
    uint32_t sweep_max_prims = 8;
    /// Subtrees with more primitives than this are built as OpenMP tasks.
    uint32_t parallel_threshold = 4096;
    /// Reinsertion: inner nodes removed and reinserted per round (the most inefficient ones), as a
    /// fraction of all inner nodes. 0.1: nearly 90% of the SAH reduction of 1.0 in an eighth
    /// of the build time.
    float reinsert_batch_fraction = 0.1f;
    /// Reinsertion: at most this many rounds ...
    uint32_t reinsert_max_rounds = 100;
    /// ... and it stops after two rounds in a row that lower the SAH cost by less than this fraction.
    float reinsert_min_gain = 0.001f;
    /// Spatial splits (sbvh): at most this many references per primitive in all leaves.
    float sbvh_reference_budget = 1.3f;
    /// Spatial splits are tried only where the best object split's children overlap by
    /// more than this fraction of the root's surface area (Stich et al.'s alpha).
    float sbvh_overlap_alpha = 1e-5f;
    /// Reinsertion's collapse: a leaf holding a primitive whose box has at least this share
    /// of the root box's surface area (a floor, a ceiling) counts its primitives
    /// large_leaf_cost_factor times. The surface-area probability assumes rays from outside;
    /// rays that start inside a room cross such a slab far more often than its area share
    /// says, and a leaf of a whole slab (twelve triangles) makes every one of them test all
    /// its faces (docs/performance.md, "Large primitives' leaves"). 0: off.
    float large_leaf_area_share = 0.1f;
    float large_leaf_cost_factor = 2.0f;
};

/// Inputs of a build: one box and one centre per primitive (same length).
struct BvhBuildInput {
    std::span<const Bounds3> boxes;
    std::span<const Vec3> centers;
    /// Only the spatial-split builder reads these: primitive i < triangle_indices.size() / 3
    /// is the triangle positions[triangle_indices[3i .. 3i + 2]], which it clips to split
    /// planes; every other primitive is clipped as its box.
    std::span<const Vec3> positions = {};
    std::span<const uint32_t> triangle_indices = {};
};

/// Builds a BVH with the chosen builder (automatic: binned, as for an unknown workload). Primitives with
/// empty boxes are kept (they land in some leaf but can never be reached by a ray). Only sbvh may reference
/// a primitive from several leaves (never twice in one leaf).
Bvh build_bvh(const BvhBuildInput& input, BvhBuilder builder, const BvhBuildParams& params = {});

/// What the automatic builder choice reads about a scene.
struct BvhWorkload {
    size_t primitives = 0;
    double expected_rays = 0;  ///< rays the render will trace; 0 when unknown
    /// Share of the primitives' summed box surface area held by the largest 1% of
    /// them: 0.03-0.16 for scanned and modelled objects, near 1 for interiors, whose
    /// walls, floors and long planks overlap most other boxes and spoil top-down splits.
    double largest_share = 0;
};

/// What BvhBuilder::automatic builds: reinsert when largest_share >= kAutoMinLargestShare,
/// expected_rays >= kAutoMinRaysPerPrimitive * primitives (its slower build repaid by
/// faster rays) and there are at least 1,000 primitives; binned otherwise (also when
/// the ray count is unknown). Spatial splits (sbvh) are never chosen: on interiors
/// reinsertion gives the better tree at half their build time. The
/// measurements behind it: docs/performance.md, "Choosing the builder".
BvhBuilder choose_bvh_builder(const BvhWorkload& workload);
inline constexpr double kAutoMinLargestShare = 0.5;
inline constexpr double kAutoMinRaysPerPrimitive = 100.0;
/// Whether a scene of this many primitives and this largest_share (BvhWorkload) is
/// treated as an interior: at least 1,000 primitives and largest_share >=
/// kAutoMinLargestShare (what makes the automatic builder pick reinsert).
bool looks_like_interior(size_t primitives, double largest_share);
/// The largest_share of these boxes (BvhWorkload). With a threshold > 0, a share that the
/// largest box already shows to be below it (the 1% largest boxes cover at most 1% of
/// the boxes times the largest area) comes back as that upper bound, still below the
/// threshold, without the selection of the largest boxes: enough to compare with it.
double largest_box_area_share(std::span<const Bounds3> boxes, double threshold = 0.0);

/// Insertion-based reinsertion (Bittner, Hapala, Havran 2013) on `bvh`, built
/// over `prim_boxes`, then an SAH-optimal collapse of subtrees into leaves of at
/// most params.max_leaf_size primitives. The SAH cost of the result is never
/// above that of `bvh` (the input, collapsed the same way, is the fallback).
Bvh reinsert_optimize_bvh(const Bvh& bvh, std::span<const Bounds3> prim_boxes, const BvhBuildParams& params);

/// Traversal stack depth: builders switch to median splits past
/// kBvhMedianSplitDepth, which bounds the depth of any tree by
/// kBvhMedianSplitDepth + log2(2^30 primitives) < kBvhMaxDepth.
inline constexpr int kBvhMaxDepth = 64;
inline constexpr int kBvhMedianSplitDepth = 32;

/// Parses a bvh_builder_name(); returns false for anything else.
bool parse_bvh_builder(std::string_view text, BvhBuilder& out);
/// "binned", "sweep", "reinsert", "sbvh" or "auto".
const char* bvh_builder_name(BvhBuilder builder);

/// Whether a layout keeps its leaf triangles in TriangleBlock4s (wide8).
inline bool layout_has_blocks(BvhLayout layout) { return layout == BvhLayout::wide8; }

/// "pairs" or "wide8".
const char* bvh_layout_name(BvhLayout layout);
/// The accepted --layout values, for usage errors: "wide8|pairs".
inline constexpr const char* kBvhLayoutChoices = "wide8|pairs";
/// Parses a bvh_layout_name(); returns false for anything else.
bool parse_bvh_layout(std::string_view text, BvhLayout& out);

}  // namespace sahara
