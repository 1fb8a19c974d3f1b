/// Spatial-split BVH (Stich, Friedrich, Dietrich, "Spatial Splits in Bounding Volume
/// Hierarchies", 2009). Each node weighs a binned object split (the references'
/// centroids) against a binned spatial split, which cuts the node's box by a plane and
/// puts a triangle crossing it into both children, each child bounding only its part
/// (the triangle clipped to the child's side). Spatial splits are tried only where the
/// object split's children overlap by a noticeable share of the scene's area (alpha),
/// and only while the total reference count stays within params.sbvh_reference_budget
/// times the primitive count: the root gets the budget's extra references, and each split
/// passes what it leaves unused to its children in proportion to their reference counts
/// (a shared counter would give the extra references to whichever task asked first, and
/// the tree would depend on thread timing). A crossing reference goes whole to one side instead when
/// that is cheaper by the SAH ("reference unsplitting").
///
/// The result is an ordinary Bvh whose prim_indices may name a primitive more than
/// once (in different leaves, never twice in one leaf).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>
#include <vector>

#include "accel/bvh_sbvh.h"
#include "accel/build_team.h"

namespace sahara {

namespace {

/// One reference: a primitive, or the part of it inside `box`.
struct Ref {
    Bounds3 box;
    uint32_t prim;
};

constexpr int kObjectBins = 32;
constexpr int kSpatialBins = 32;

struct ObjectSplit {
    int axis = -1;
    int bin = 0;  ///< references whose centroid bin is below go left
    float cost = kInfinity;
    Bounds3 left, right;
};

struct SpatialSplit {
    int axis = -1;
    float plane = 0.0f;
    float cost = kInfinity;
    Bounds3 left, right;
    uint32_t n_left = 0, n_right = 0;
};

/// Bin of a scaled coordinate f: clamped to [0, bins - 1], NaN (0 times an infinite
/// scale over a denormal extent) to bin 0, never an out-of-range float-to-int conversion.
int clamp_bin(float f, int bins) { return f > 0.0f ? int(std::min(f, float(bins - 1))) : 0; }

Bounds3 intersect_boxes(const Bounds3& a, const Bounds3& b) {
    Bounds3 r{max(a.lo, b.lo), min(a.hi, b.hi)};
    return r.empty() ? Bounds3{} : r;
}

/// A float box around a double point, rounded outward on every axis but `axis` (whose
/// coordinate is the exact plane): bounds from clipping must never cut off a hit.
void extend_outward(Bounds3& box, const double p[3], int axis, float plane) {
    Vec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
        if (a == axis) {
            lo[a] = hi[a] = plane;
            continue;
        }
        const auto f = float(p[a]);
        lo[a] = std::nextafter(f, -kInfinity);
        hi[a] = std::nextafter(f, kInfinity);
    }
    box.extend(lo);
    box.extend(hi);
}

}  // namespace

Bounds3 clip_triangle_to_slab(const Vec3 v[3], int axis, float lo, float hi) {
    // The triangle's part in the slab is a convex polygon whose corners are the
    // triangle's corners inside the slab and the edges' crossings of the two planes.
    Bounds3 out;
    for (int i = 0; i < 3; ++i) {
        const Vec3& a = v[i];
        const Vec3& b = v[(i + 1) % 3];
        if (a[axis] >= lo && a[axis] <= hi) out.extend(a);
        for (const float plane : {lo, hi}) {
            if ((a[axis] < plane) == (b[axis] < plane)) continue;
            const double t = (double(plane) - double(a[axis])) / (double(b[axis]) - double(a[axis]));
            const double p[3] = {double(a.x) + t * (double(b.x) - double(a.x)),
                                 double(a.y) + t * (double(b.y) - double(a.y)),
                                 double(a.z) + t * (double(b.z) - double(a.z))};
            extend_outward(out, p, axis, plane);
        }
    }
    return out;
}

namespace {

/// Rewrites `bvh` with its pairs in depth-first order (left subtree first, as a serial
/// build allocates them) and its slots in the order of the leaves, so that every
/// subtree's slots are contiguous. The parallel build hands out pairs and slots in the
/// order tasks happen to finish, and the wide collapse merges only leaves whose slots
/// are contiguous: without this, the tree at two threads depended on timing.
void renumber_depth_first(Bvh& bvh) {
    if (bvh.nodes.size() <= 1) return;  // a leaf root's slots are one range already
    decltype(bvh.nodes) nodes(bvh.nodes.size());
    std::vector<uint32_t> slots;
    slots.reserve(bvh.prim_indices.size());
    nodes[1] = bvh.nodes[1];  // padding
    uint32_t next_pair = Bvh::kFirstPair;
    std::vector<std::pair<uint32_t, uint32_t>> stack{{0, 0}};  // (old node, its new place)
    while (!stack.empty()) {
        const auto [old_id, new_id] = stack.back();
        stack.pop_back();
        BvhNode node = bvh.nodes[old_id];
        if (node.is_leaf()) {
            const auto first = bvh.prim_indices.begin() + std::ptrdiff_t(node.index);
            node.index = uint32_t(slots.size());
            slots.insert(slots.end(), first, first + std::ptrdiff_t(node.count));
        } else {
            stack.push_back({node.index + 1, next_pair + 1});
            stack.push_back({node.index, next_pair});
            node.index = next_pair;
            next_pair += 2;
        }
        nodes[new_id] = node;
    }
    bvh.nodes = std::move(nodes);
    bvh.prim_indices = std::move(slots);
}

class SbvhBuild {
   public:
    SbvhBuild(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out)
        : in_(input), params_(params), out_(out) {}

    void run() {
        const auto n = uint32_t(in_.boxes.size());
        if (n == 0) return;
        std::vector<Ref> refs(n);
        Bounds3 root;
        for (uint32_t i = 0; i < n; ++i) {
            refs[i] = Ref{in_.boxes[i], i};
            root.extend(in_.boxes[i]);
        }
        root_area_ = root.surface_area();
        budget_ =
            std::max<size_t>(n, size_t(double(n) * double(std::max(params_.sbvh_reference_budget, 1.0f))));
        out_.prim_indices.resize(budget_);
        out_.nodes.resize(2 * budget_);
        node_count_ = Bvh::kFirstPair;
        build::with_build_team([&] { build_node(0, std::move(refs), 0, budget_ - n); });
        out_.nodes.resize(out_.nodes[0].is_leaf() ? 1 : node_count_.load());
        if (out_.nodes.size() > 1) out_.nodes[1] = BvhNode{{0, 0, 0, 0, 0, 0}, 0, 0};
        out_.prim_indices.resize(slot_count_.load());
        renumber_depth_first(out_);
    }

   private:
    uint32_t triangle_count() const { return uint32_t(in_.triangle_indices.size() / 3); }

    Bounds3 clip(const Ref& r, int axis, float lo, float hi) const {
        Bounds3 part;
        if (r.prim < triangle_count()) {
            const uint32_t* t = &in_.triangle_indices[3 * size_t(r.prim)];
            const Vec3 v[3] = {in_.positions[t[0]], in_.positions[t[1]], in_.positions[t[2]]};
            part = clip_triangle_to_slab(v, axis, lo, hi);
        } else {
            part = r.box;  // other kinds: their box, cut by the slab
            part.lo[axis] = std::max(part.lo[axis], lo);
            part.hi[axis] = std::min(part.hi[axis], hi);
        }
        return intersect_boxes(part, r.box);
    }

    float blocked(uint32_t n) const {
        const uint32_t b = params_.leaf_block_size;
        return float((n + b - 1) / b * b);
    }

    float sah(const Bounds3& l, uint32_t nl, const Bounds3& r, uint32_t nr) const {
        return params_.intersection_cost * (l.surface_area() * blocked(nl) + r.surface_area() * blocked(nr));
    }

    static Vec3 centroid(const Ref& r) { return r.box.empty() ? Vec3(0.0f) : r.box.center(); }

    ObjectSplit find_object_split(const std::vector<Ref>& refs, const Bounds3& cents) const {
        ObjectSplit best;
        for (int axis = 0; axis < 3; ++axis) {
            const float lo = cents.lo[axis], ext = cents.hi[axis] - lo;
            if (!(ext > 0.0f)) continue;
            const float scale = float(kObjectBins) / ext;
            Bounds3 box[kObjectBins];
            uint32_t count[kObjectBins] = {};
            for (const Ref& r : refs) {
                const int b = clamp_bin((centroid(r)[axis] - lo) * scale, kObjectBins);
                box[b].extend(r.box);
                ++count[b];
            }
            Bounds3 right[kObjectBins];
            uint32_t n_right[kObjectBins] = {};
            Bounds3 acc;
            uint32_t n = 0;
            for (int b = kObjectBins - 1; b > 0; --b) {
                acc.extend(box[b]);
                n += count[b];
                right[b] = acc;
                n_right[b] = n;
            }
            acc = Bounds3{};
            n = 0;
            for (int b = 1; b < kObjectBins; ++b) {
                acc.extend(box[b - 1]);
                n += count[b - 1];
                if (n == 0 || n_right[b] == 0) continue;
                const float cost = sah(acc, n, right[b], n_right[b]);
                if (cost < best.cost) best = ObjectSplit{axis, b, cost, acc, right[b]};
            }
        }
        return best;
    }

    /// Bin b of the node's `axis` spans [plane(b), plane(b + 1)].
    static float bin_plane(const Bounds3& box, int axis, int b) {
        if (b >= kSpatialBins) return box.hi[axis];
        return box.lo[axis] + (box.hi[axis] - box.lo[axis]) * (float(b) / float(kSpatialBins));
    }

    static int bin_of(const Bounds3& box, int axis, float x) {
        const float ext = box.hi[axis] - box.lo[axis];
        return clamp_bin((x - box.lo[axis]) * (float(kSpatialBins) / ext), kSpatialBins);
    }

    SpatialSplit find_spatial_split(const std::vector<Ref>& refs, const Bounds3& node) const {
        SpatialSplit best;
        for (int axis = 0; axis < 3; ++axis) {
            if (!(node.hi[axis] > node.lo[axis])) continue;
            Bounds3 box[kSpatialBins];
            uint32_t enter[kSpatialBins] = {}, leave[kSpatialBins] = {};
            for (const Ref& r : refs) {
                if (r.box.empty()) continue;
                const int b0 = bin_of(node, axis, r.box.lo[axis]);
                const int b1 = bin_of(node, axis, r.box.hi[axis]);
                ++enter[b0];
                ++leave[b1];
                if (b0 == b1) {
                    box[b0].extend(r.box);
                    continue;
                }
                for (int b = b0; b <= b1; ++b)
                    box[b].extend(clip(r, axis, bin_plane(node, axis, b), bin_plane(node, axis, b + 1)));
            }
            sweep_spatial(axis, node, box, enter, leave, best);
        }
        return best;
    }

    void sweep_spatial(int axis, const Bounds3& node, const Bounds3* box, const uint32_t* enter,
                       const uint32_t* leave, SpatialSplit& best) const {
        Bounds3 right[kSpatialBins];
        uint32_t n_right[kSpatialBins] = {};
        Bounds3 acc;
        uint32_t n = 0;
        for (int b = kSpatialBins - 1; b > 0; --b) {
            acc.extend(box[b]);
            n += leave[b];
            right[b] = acc;
            n_right[b] = n;
        }
        acc = Bounds3{};
        n = 0;
        for (int b = 1; b < kSpatialBins; ++b) {
            acc.extend(box[b - 1]);
            n += enter[b - 1];
            if (n == 0 || n_right[b] == 0) continue;
            const float cost = sah(acc, n, right[b], n_right[b]);
            if (cost < best.cost)
                best = SpatialSplit{axis, bin_plane(node, axis, b), cost, acc, right[b], n, n_right[b]};
        }
    }

    void make_leaf(BvhNode& node, const std::vector<Ref>& refs) {
        const auto n = uint32_t(refs.size());
        const uint32_t first = slot_count_.fetch_add(n);
        for (uint32_t i = 0; i < n; ++i) out_.prim_indices[first + i] = refs[i].prim;
        node.index = first;
        node.count = n;
    }

    /// Builds the subtree of `refs` at node_id; it may add up to `extra` references.
    void build_node(uint32_t node_id, std::vector<Ref> refs, int depth, size_t extra) {
        Bounds3 box, cents;
        for (const Ref& r : refs) {
            box.extend(r.box);
            cents.extend(centroid(r));
        }
        BvhNode& node = out_.nodes[node_id];
        node.set_box(box);
        std::vector<Ref> left, right;
        const size_t n = refs.size();
        if (!split(refs, box, cents, depth, extra, left, right)) {
            make_leaf(node, refs);
            return;
        }
        refs = std::vector<Ref>();  // the parent's references are no longer needed
        const size_t unused = extra - (left.size() + right.size() - n);
        const size_t left_extra =
            size_t(double(unused) * double(left.size()) / double(left.size() + right.size()));
        const uint32_t first_child = node_count_.fetch_add(2);
        node.index = first_child;
        node.count = 0;
        if (left.size() + right.size() > params_.parallel_threshold) {
            auto* mine = new std::vector<Ref>(std::move(left));
#pragma omp task default(shared) firstprivate(first_child, mine, depth, left_extra)
            {
                build_node(first_child, std::move(*mine), depth + 1, left_extra);
                delete mine;
            }
        } else {
            build_node(first_child, std::move(left), depth + 1, left_extra);
        }
        build_node(first_child + 1, std::move(right), depth + 1, unused - left_extra);
    }

    /// Chooses leaf (false) or a split of `refs` into `left` and `right` (true).
    bool split(std::vector<Ref>& refs, const Bounds3& box, const Bounds3& cents, int depth, size_t extra,
               std::vector<Ref>& left, std::vector<Ref>& right) {
        const auto n = uint32_t(refs.size());
        if (n <= 1) return false;
        const bool may_be_leaf = n <= params_.max_leaf_size;
        if (depth >= kBvhMedianSplitDepth) return !may_be_leaf && median_split(refs, cents, left, right);
        const ObjectSplit object = find_object_split(refs, cents);
        SpatialSplit spatial;
        const Bounds3 overlap = intersect_boxes(object.left, object.right);
        if (object.axis < 0 || overlap.surface_area() > params_.sbvh_overlap_alpha * root_area_)
            spatial = find_spatial_split(refs, box);
        const float best = std::min(object.cost, spatial.cost);
        if (best == kInfinity) return !may_be_leaf && median_split(refs, cents, left, right);
        const float area = box.surface_area();
        if (may_be_leaf &&
            params_.intersection_cost * blocked(n) * area <= params_.traversal_cost * area + best)
            return false;
        if (spatial.cost < object.cost && spatial_partition(refs, spatial, extra, left, right)) return true;
        if (object.axis >= 0) {
            object_partition(refs, object, cents, left, right);
            return true;
        }
        return median_split(refs, cents, left, right);
    }

    void object_partition(const std::vector<Ref>& refs, const ObjectSplit& s, const Bounds3& cents,
                          std::vector<Ref>& left, std::vector<Ref>& right) const {
        const float lo = cents.lo[s.axis];
        const float scale = float(kObjectBins) / (cents.hi[s.axis] - lo);
        for (const Ref& r : refs) {
            const int b = clamp_bin((centroid(r)[s.axis] - lo) * scale, kObjectBins);
            (b < s.bin ? left : right).push_back(r);
        }
    }

    bool median_split(std::vector<Ref>& refs, const Bounds3& cents, std::vector<Ref>& left,
                      std::vector<Ref>& right) const {
        const int axis = max_dimension(cents.extent());
        const auto mid = refs.begin() + std::ptrdiff_t(refs.size() / 2);
        std::nth_element(refs.begin(), mid, refs.end(), [axis](const Ref& a, const Ref& b) {
            const float ca = centroid(a)[axis], cb = centroid(b)[axis];
            return ca < cb || (ca == cb && a.prim < b.prim);
        });
        left.assign(refs.begin(), mid);
        right.assign(mid, refs.end());
        return true;
    }

    bool spatial_partition(const std::vector<Ref>& refs, const SpatialSplit& s, size_t extra,
                           std::vector<Ref>& left, std::vector<Ref>& right);

    const BvhBuildInput& in_;
    BvhBuildParams params_;
    Bvh& out_;
    float root_area_ = 0.0f;
    size_t budget_ = 0;
    std::atomic<uint32_t> node_count_{0};
    std::atomic<uint32_t> slot_count_{0};
};

/// Splits `refs` at the plane: references on one side go there, crossing ones go whole
/// to one side where the SAH prefers that (unsplitting), otherwise both sides get their
/// clipped part. False (nothing changed) when the duplicates the split wants exceed the
/// subtree's `extra` references or a side would be empty.
bool SbvhBuild::spatial_partition(const std::vector<Ref>& refs, const SpatialSplit& s, size_t extra,
                                  std::vector<Ref>& left, std::vector<Ref>& right) {
    const size_t n = refs.size();
    const size_t wanted = s.n_left + s.n_right > n ? s.n_left + s.n_right - n : 0;
    if (wanted > extra) return false;
    size_t duplicates = 0;
    const float a_left = s.left.surface_area(), a_right = s.right.surface_area();
    const float n_left = blocked(s.n_left), n_right = blocked(s.n_right);
    const int axis = s.axis;
    for (const Ref& r : refs) {
        if (r.box.empty() || r.box.hi[axis] <= s.plane) {
            left.push_back(r);
            continue;
        }
        if (r.box.lo[axis] >= s.plane) {
            right.push_back(r);
            continue;
        }
        const float split_cost = a_left * n_left + a_right * n_right;
        const float to_left = join(s.left, r.box).surface_area() * n_left + a_right * (n_right - 1.0f);
        const float to_right = a_left * (n_left - 1.0f) + join(s.right, r.box).surface_area() * n_right;
        const Bounds3 lpart = clip(r, axis, -kInfinity, s.plane);
        const Bounds3 rpart = clip(r, axis, s.plane, kInfinity);
        const bool keep_split = duplicates < wanted && split_cost < std::min(to_left, to_right) &&
                                !lpart.empty() && !rpart.empty();
        if (keep_split) {
            left.push_back(Ref{lpart, r.prim});
            right.push_back(Ref{rpart, r.prim});
            ++duplicates;
        } else if (to_left <= to_right) {
            left.push_back(r);
        } else {
            right.push_back(r);
        }
    }
    if (!left.empty() && !right.empty()) return true;
    left.clear();
    right.clear();
    return false;
}

}  // namespace

void build_sbvh(const BvhBuildInput& input, const BvhBuildParams& params, Bvh& out) {
    SbvhBuild(input, params, out).run();
}

}  // namespace sahara
