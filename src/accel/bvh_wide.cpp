#include "accel/bvh_wide.h"
#include "accel/build_team.h"

#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "base/error.h"

namespace sahara {

namespace {

float half_area(const BvhNode& n) {
    const float dx = n.bounds[1] - n.bounds[0], dy = n.bounds[3] - n.bounds[2],
                dz = n.bounds[5] - n.bounds[4];
    return dx < 0.0f ? 0.0f : dx * dy + dy * dz + dz * dx;
}

/// Which binary-tree nodes become the children of each N-wide node, and which
/// small subtrees become one leaf. The cost is the wide tree's SAH: summed surface
/// area of its nodes (the expected node visits of a random ray, up to the root's
/// area) plus `block_cost` times each leaf's area and block count. A dynamic
/// programme over the binary tree minimises it exactly (the collapse step of
/// Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through
/// Compressed Wide BVHs", 2017). The usual greedy rule, opening the largest
/// inner child until N are gathered, leaves more node area.
template <int N>
class CollapsePlan {
   public:
    CollapsePlan(const Bvh& bvh, const WideCollapse& opt) : bvh_(bvh), opt_(opt), table_(bvh.nodes.size()) {
        // Each node's costs depend only on its children's, so the subtrees below the
        // top levels are independent tasks; the result does not depend on the threads.
        if (bvh.nodes.size() < opt.parallel_min_nodes) {
            solve(0);
            return;
        }
        build::with_build_team([&] { spawn(0, 1); });
    }

    /// One child of a wide node: binary node `node`, or the leaf of slots [first, first + count).
    struct Child {
        uint32_t node;
        uint32_t first, count;  ///< count 0: an inner node
    };

    /// The children of the N-wide node made for binary inner node `inner`.
    int children(uint32_t inner, Child out[N]) const {
        int n = 0;
        const uint32_t first = bvh_.nodes[inner].index;
        const int j = table_[inner].plan.left_slots[N];
        emit(first, j, out, n);
        emit(first + 1, N - j, out, n);
        return n;
    }

   private:
    using Costs = std::array<double, N + 1>;  ///< [k]: least cost of a subtree in k slots
    struct Choice {
        std::array<uint8_t, N + 1> left_slots;  ///< [k]: slots of the left child when opened
        std::array<bool, N + 1> open;           ///< [k]: opened into k slots, or kept as one child
        bool leaf;                              ///< kept as one child: a leaf, not a node
    };
    /// Tasks are made for the subtrees below the first kTaskLevels levels.
    static constexpr int kTaskLevels = 6;
    static constexpr uint32_t kTopNodes = 1u << kTaskLevels;  ///< top positions: [1, kTopNodes)
    /// A node of the top levels: its binary node, and how many of its children are solved.
    struct Top {
        uint32_t node = 0;
        std::atomic<uint32_t> ended{0};
    };
    struct Range {
        uint32_t first, count;  ///< the subtree's slots; first = kNoNode: not contiguous
    };
    /// Node x's share of the programme, in one array (one allocation, read together).
    struct Entry {
        Costs cost;  ///< [k]: least cost of subtree x in k slots
        Choice plan;
        Range range;
    };
    /// Costs and choices of the subtree of node x, children first.
    void solve(uint32_t x) {
        const BvhNode& node = bvh_.nodes[x];
        if (!node.is_leaf()) {
            solve(node.index);
            solve(node.index + 1);
        }
        combine(x);
    }

    /// solve() of node x at position h of the top levels (1: the root, 2h and 2h + 1: its
    /// children): a task per subtree below them. No task waits for another (libgomp's
    /// taskwait would idle the thread until that very child ended): the second of two
    /// siblings to end combines their parent (finish()).
    void spawn(uint32_t x, uint32_t h) {
        const BvhNode& node = bvh_.nodes[x];
        if (h >= kTopNodes || node.is_leaf()) {
            solve(x);
            finish(h);
            return;
        }
        top_[h].node = x;
        top_[h].ended.store(0, std::memory_order_relaxed);
        const uint32_t left = node.index;
#pragma omp task default(shared) firstprivate(left, h)
        spawn(left, 2 * h);
        spawn(left + 1, 2 * h + 1);
    }

    /// After the subtree at top position h is solved: its parent is combined by whichever
    /// of its two children ends second, and so on up.
    void finish(uint32_t h) {
        for (; h > 1; h /= 2) {
            Top& parent = top_[h / 2];
            if (parent.ended.fetch_add(1, std::memory_order_acq_rel) == 0) return;
            combine(parent.node);
        }
    }

    /// opened[k]: the least cost of both children sharing k slots of the parent's node, the
    /// left child's share in plan.left_slots[k] (the first best). Branch-free: which share
    /// wins is data-dependent. Two leaves cost the same in any slots, so j = 1 wins.
    static Costs open_costs(const Costs& left, const Costs& right, bool left_leaf, bool right_leaf,
                            Choice& plan) {
        const bool two_leaves = left_leaf && right_leaf;
        constexpr double inf = std::numeric_limits<double>::infinity();
        Costs opened;
        opened.fill(inf);
        if (two_leaves) {
            const double sum = left[1] + right[1];
            if (!(sum < inf)) return opened;
            for (int k = 2; k <= N; ++k) opened[k] = sum, plan.left_slots[k] = 1;
            return opened;
        }
        if (right_leaf) {
            // right[k - j] is the same for every k: the loop below in one pass over j.
            double best = inf;
            int best_j = 0;
            for (int k = 2; k <= N; ++k) {
                const double c = left[k - 1] + right[1];
                const bool lower = c < best;
                best = lower ? c : best;
                best_j = lower ? k - 1 : best_j;
                opened[k] = best;
                plan.left_slots[k] = uint8_t(best_j);
            }
            return opened;
        }
        if (left_leaf && non_increasing(right) && std::isfinite(left[1])) {
            // left[j] is the same for every j and right[k - j] grows with j (rounding is
            // monotonic), so the loop below would pick j = 1.
            for (int k = 2; k <= N; ++k) {
                const double c = left[1] + right[k - 1];
                const bool finite = c < inf;
                opened[k] = finite ? c : inf;
                plan.left_slots[k] = uint8_t(finite ? 1 : 0);
            }
            return opened;
        }
        for (int k = 2; k <= N; ++k) {
            double best = inf;
            int best_j = 0;
            for (int j = 1; j < k; ++j) {
                const double c = left[j] + right[k - j];
                const bool lower = c < best;
                best = lower ? c : best;
                best_j = lower ? j : best_j;
            }
            opened[k] = best;
            plan.left_slots[k] = uint8_t(best_j);
        }
        return opened;
    }

    /// The collapse's dynamic programme at node x, its children solved.
    void combine(uint32_t x) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        const BvhNode& node = bvh_.nodes[x];
        const double area = double(half_area(node));
        Entry& e = table_[x];
        Costs& f = e.cost;
        if (node.is_leaf()) {
            e.range = {node.index, node.count};
            f.fill(opt_.block_cost * area * double(blocks(node.count)));
            return;
        }
        Choice& plan = e.plan;
        plan = Choice{};
        const Range& l = table_[node.index].range;
        const Range& r = table_[node.index + 1].range;
        // A subtree whose primitives are contiguous slots may become one leaf.
        const bool contiguous = l.first != kNoNode && r.first == l.first + l.count;
        e.range = contiguous ? Range{l.first, l.count + r.count} : Range{kNoNode, 0};
        const Costs& left = table_[node.index].cost;
        const Costs& right = table_[node.index + 1].cost;
        const Costs opened = open_costs(left, right, bvh_.nodes[node.index].is_leaf(),
                                        bvh_.nodes[node.index + 1].is_leaf(), plan);
        // As one child, x is a node of its own (its area plus its children in N
        // slots) or, when small enough, a leaf.
        const double as_node = area + opened[N];
        const double as_leaf = contiguous && e.range.count <= opt_.merge_leaves_up_to
                                   ? opt_.block_cost * area * double(blocks(e.range.count))
                                   : inf;
        plan.leaf = as_leaf < as_node;
        f[1] = std::min(as_node, as_leaf);
        for (int k = 2; k <= N; ++k) {
            plan.open[k] = opened[k] < f[1];
            f[k] = plan.open[k] ? opened[k] : f[1];
        }
    }

    static uint32_t blocks(uint32_t count) { return (count + 3) / 4; }

    /// c[1] >= c[2] >= ... >= c[N - 1], none NaN.
    static bool non_increasing(const Costs& c) {
        bool yes = true;
        for (int k = 1; k + 1 < N; ++k) yes &= c[k] >= c[k + 1];
        return yes;
    }

    void emit(uint32_t x, int k, Child out[N], int& n) const {
        const BvhNode& node = bvh_.nodes[x];
        if (node.is_leaf()) {
            if (node.count > kMaxWideLeafCount)
                throw std::invalid_argument("wide BVH leaves hold at most " +
                                            std::to_string(kMaxWideLeafCount) +
                                            " primitives (BvhBuildParams::max_leaf_size)");
            out[n++] = {x, node.index, node.count};
        } else if (table_[x].plan.open[k]) {
            const int j = table_[x].plan.left_slots[k];
            emit(node.index, j, out, n);
            emit(node.index + 1, k - j, out, n);
        } else {
            const Entry& e = table_[x];
            out[n++] = {x, e.plan.leaf ? e.range.first : 0, e.plan.leaf ? e.range.count : 0};
        }
    }

    const Bvh& bvh_;
    const WideCollapse opt_;
    BuildArray<Entry> table_;  ///< [x]: subtree x's costs, choices and slots
    std::array<Top, kTopNodes> top_;
};

/// Child slot `c` of `p`: the box of binary node `box`, a leaf of `count` slots
/// from `first`, or (count 0) an inner node, patched when its node is placed.
template <int N>
void set_child(BvhWideNode<N>& p, int c, const BvhNode& box, uint32_t first, uint32_t count) {
    p.lo_x[c] = box.bounds[0];
    p.hi_x[c] = box.bounds[1];
    p.lo_y[c] = box.bounds[2];
    p.hi_y[c] = box.bounds[3];
    p.lo_z[c] = box.bounds[4];
    p.hi_z[c] = box.bounds[5];
    p.child[c] = count ? wide_leaf_ref(first, count) : kNoNode;
}

template <int N>
BvhWideNode<N> empty_node() {
    BvhWideNode<N> p{};
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (int c = 0; c < N; ++c) {
        p.lo_x[c] = p.lo_y[c] = p.lo_z[c] = inf;
        p.hi_x[c] = p.hi_y[c] = p.hi_z[c] = -inf;
        p.child[c] = kNoNode;
    }
    return p;
}

}  // namespace

template <int N>
BvhWide<N> make_bvh_wide(const Bvh& bvh, const WideCollapse& opt) {
    BvhWide<N> out;
    if (bvh.empty()) return out;
    out.empty = false;
    out.root = bvh.nodes[0];
    if (out.root.is_leaf()) return out;
    // Leaf references hold the first slot and the count in one word (wide_leaf_ref).
    if (bvh.prim_indices.size() > size_t(kMaxWideLeafFirst) + 1)
        throw InputError("scene too large: " + std::to_string(bvh.prim_indices.size()) +
                         " primitives, more than the " + std::to_string(size_t(kMaxWideLeafFirst) + 1) +
                         " that a wide BVH's leaf references reach");
    if (opt.merge_leaves_up_to > kMaxWideLeafCount)
        throw std::invalid_argument("wide BVH leaves hold at most " + std::to_string(kMaxWideLeafCount) +
                                    " primitives (WideCollapse::merge_leaves_up_to)");
    out.nodes.reserve(bvh.nodes.size() / (N - 1) + 1);
    // Depth-first: (canonical inner node, wide node that must point at it, child slot).
    struct Pending {
        uint32_t node;
        uint32_t parent;
        int slot;
    };
    const CollapsePlan<N> plan(bvh, opt);
    std::vector<Pending> stack{{0, kNoNode, 0}};
    while (!stack.empty()) {
        const Pending it = stack.back();
        stack.pop_back();
        const auto index = uint32_t(out.nodes.size());
        if (it.parent != kNoNode) out.nodes[it.parent].child[it.slot] = BvhWide<N>::offset_of(index);
        typename CollapsePlan<N>::Child kids[N];
        const int n = plan.children(it.node, kids);
        BvhWideNode<N> p = empty_node<N>();
        for (int c = 0; c < n; ++c) set_child(p, c, bvh.nodes[kids[c].node], kids[c].first, kids[c].count);
        out.nodes.push_back(p);
        for (int c = n - 1; c >= 0; --c)
            if (!kids[c].count) stack.push_back({kids[c].node, index, c});
    }
    if (out.nodes.size() > BvhWide<N>::kMaxNodes)
        throw InputError("scene too large: its wide BVH has " + std::to_string(out.nodes.size()) +
                         " nodes, more than the " + std::to_string(BvhWide<N>::kMaxNodes) +
                         " that 32-bit node offsets reach");
    return out;
}

template Bvh8 make_bvh_wide<8>(const Bvh& bvh, const WideCollapse& opt);

}  // namespace sahara
