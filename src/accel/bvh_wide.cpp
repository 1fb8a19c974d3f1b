#include "accel/bvh_wide.h"

#include <array>
#include <atomic>
#include <exception>
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
    CollapsePlan(const Bvh& bvh, const WideCollapse& opt)
        : bvh_(bvh),
          opt_(opt),
          cost_(bvh.nodes.size()),
          plan_(bvh.nodes.size()),
          range_(bvh.nodes.size()),
          wide_(bvh.nodes.size()) {}

    /// Whether the tree is large enough for tasks (inside a parallel region).
    bool parallel() const { return bvh_.nodes.size() >= kParallelNodes; }

    /// Solves the programme for the whole tree. Each node's costs depend only on its
    /// children's, so the subtrees below the top levels are independent tasks (when
    /// parallel()); the result does not depend on the threads. Returns after every task.
    void solve() { solve(0, parallel() ? 0 : kTaskLevels); }

    /// Wide nodes below the one made for binary inner node x (its whole subtree but itself).
    uint32_t nodes_below(uint32_t x) const { return wide_[x][0]; }
    /// Whether a binary leaf holds more primitives than a wide leaf reference can.
    bool oversize_leaf() const { return oversize_.load(std::memory_order_relaxed); }

    /// One child of a wide node: binary node `node`, or the leaf of slots [first, first + count).
    struct Child {
        uint32_t node;
        uint32_t first, count;  ///< count 0: an inner node
    };

    /// The children of the N-wide node made for binary inner node `inner`.
    int children(uint32_t inner, Child out[N]) const {
        int n = 0;
        const uint32_t first = bvh_.nodes[inner].index;
        const int j = plan_[inner].left_slots[N];
        emit(first, j, out, n);
        emit(first + 1, N - j, out, n);
        return n;
    }

   private:
    using Costs = std::array<double, N + 1>;  ///< [k]: least cost of a subtree in k slots
    /// [k], k >= 1: wide nodes the subtree emits in k slots (as the plan places it);
    /// [0]: wide nodes below the node made for it, its children sharing N slots.
    using NodeCounts = std::array<uint32_t, N + 1>;
    struct Choice {
        std::array<uint8_t, N + 1> left_slots;  ///< [k]: slots of the left child when opened
        std::array<bool, N + 1> open;           ///< [k]: opened into k slots, or kept as one child
        bool leaf;                              ///< kept as one child: a leaf, not a node
    };
    /// Trees with fewer nodes are solved without a parallel region; tasks are made for
    /// the subtrees of the first kTaskLevels levels.
    static constexpr size_t kParallelNodes = 1u << 14;
    static constexpr int kTaskLevels = 6;
    struct Range {
        uint32_t first, count;  ///< the subtree's slots; first = kNoNode: not contiguous
    };
    /// Costs and choices of the subtree of node x (at `level`), children first.
    void solve(uint32_t x, int level) {
        const BvhNode& node = bvh_.nodes[x];
        if (!node.is_leaf()) {
            if (level < kTaskLevels) {
#pragma omp task default(shared) firstprivate(level)
                solve(node.index, level + 1);
                solve(node.index + 1, level + 1);
#pragma omp taskwait
            } else {
                solve(node.index, level + 1);
                solve(node.index + 1, level + 1);
            }
        }
        combine(x);
    }

    /// opened[k]: the least cost of both children sharing k slots of the parent's node, the
    /// left child's share in plan.left_slots[k] (the first best). Branch-free: which share
    /// wins is data-dependent. Two leaves cost the same in any slots, so j = 1 wins.
    static Costs open_costs(const Costs& left, const Costs& right, bool two_leaves, Choice& plan) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        Costs opened;
        opened.fill(inf);
        if (two_leaves) {
            const double sum = left[1] + right[1];
            if (!(sum < inf)) return opened;
            for (int k = 2; k <= N; ++k) opened[k] = sum, plan.left_slots[k] = 1;
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
        Costs& f = cost_[x];
        if (node.is_leaf()) {
            range_[x] = {node.index, node.count};
            f.fill(opt_.block_cost * area * double(blocks(node.count)));
            wide_[x].fill(0);
            if (node.count > kMaxWideLeafCount) oversize_.store(true, std::memory_order_relaxed);
            return;
        }
        Choice& plan = plan_[x];
        plan = Choice{};
        const Range& l = range_[node.index];
        const Range& r = range_[node.index + 1];
        // A subtree whose primitives are contiguous slots may become one leaf.
        const bool contiguous = l.first != kNoNode && r.first == l.first + l.count;
        range_[x] = contiguous ? Range{l.first, l.count + r.count} : Range{kNoNode, 0};
        const Costs& left = cost_[node.index];
        const Costs& right = cost_[node.index + 1];
        const Costs opened = open_costs(
            left, right, bvh_.nodes[node.index].is_leaf() && bvh_.nodes[node.index + 1].is_leaf(), plan);
        // As one child, x is a node of its own (its area plus its children in N
        // slots) or, when small enough, a leaf.
        const double as_node = area + opened[N];
        const double as_leaf = contiguous && range_[x].count <= opt_.merge_leaves_up_to
                                   ? opt_.block_cost * area * double(blocks(range_[x].count))
                                   : inf;
        plan.leaf = as_leaf < as_node;
        f[1] = std::min(as_node, as_leaf);
        for (int k = 2; k <= N; ++k) {
            plan.open[k] = opened[k] < f[1];
            f[k] = plan.open[k] ? opened[k] : f[1];
        }
        count_nodes(x, plan);
    }

    /// wide_[x] from its children's, following the choices just made (what emit() walks).
    void count_nodes(uint32_t x, const Choice& plan) {
        const BvhNode& node = bvh_.nodes[x];
        const NodeCounts& l = wide_[node.index];
        const NodeCounts& r = wide_[node.index + 1];
        NodeCounts& w = wide_[x];
        auto opened = [&](int k) { return l[plan.left_slots[k]] + r[k - plan.left_slots[k]]; };
        w[0] = opened(N);
        w[1] = plan.leaf ? 0 : 1 + w[0];
        for (int k = 2; k <= N; ++k) w[k] = plan.open[k] ? opened(k) : w[1];
    }

    static uint32_t blocks(uint32_t count) { return (count + 3) / 4; }

    void emit(uint32_t x, int k, Child out[N], int& n) const {
        const BvhNode& node = bvh_.nodes[x];
        if (node.is_leaf()) {
            out[n++] = {x, node.index, node.count};  // its count checked by oversize_leaf()
        } else if (plan_[x].open[k]) {
            const int j = plan_[x].left_slots[k];
            emit(node.index, j, out, n);
            emit(node.index + 1, k - j, out, n);
        } else {
            out[n++] = {x, plan_[x].leaf ? range_[x].first : 0, plan_[x].leaf ? range_[x].count : 0};
        }
    }

    const Bvh& bvh_;
    const WideCollapse opt_;
    BuildArray<Costs> cost_;  ///< [x][k]: least cost of subtree x in k slots
    BuildArray<Choice> plan_;
    BuildArray<Range> range_;
    BuildArray<NodeCounts> wide_;
    std::atomic<bool> oversize_{false};
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

/// Writes the wide node made for binary inner node x at out.nodes[index] and, depth
/// first, its subtree after it: each inner child's subtree in the next plan.nodes_below()
/// + 1 places, so large subtrees are written by tasks at places known in advance (the
/// same array as a serial depth-first emission).
template <int N>
void place(const CollapsePlan<N>& plan, const Bvh& bvh, uint32_t x, uint32_t index, bool tasks,
           BvhWide<N>& out) {
    // Subtrees of fewer wide nodes are written by the task that reaches them.
    constexpr uint32_t kTaskNodes = 128;
    typename CollapsePlan<N>::Child kids[N];
    const int n = plan.children(x, kids);
    BvhWideNode<N> p = empty_node<N>();
    uint32_t next = index + 1;
    for (int c = 0; c < n; ++c) {
        set_child(p, c, bvh.nodes[kids[c].node], kids[c].first, kids[c].count);
        if (kids[c].count) continue;
        const uint32_t kid = kids[c].node, at = next;
        p.child[c] = BvhWide<N>::offset_of(at);
        next += plan.nodes_below(kid) + 1;
        if (tasks && plan.nodes_below(kid) >= kTaskNodes) {
#pragma omp task default(shared) firstprivate(kid, at)
            place(plan, bvh, kid, at, tasks, out);
        } else {
            place(plan, bvh, kid, at, tasks, out);
        }
    }
    out.nodes[index] = p;
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
    CollapsePlan<N> plan(bvh, opt);
    // One parallel region for the programme and the emission: the node count is known
    // once the programme is solved. Errors are thrown after the region.
    size_t total = 0;
    std::exception_ptr error;
#pragma omp parallel if (plan.parallel())
#pragma omp single
    {
        plan.solve();
        total = size_t(plan.nodes_below(0)) + 1;
        if (!plan.oversize_leaf() && total <= BvhWide<N>::kMaxNodes) {
            try {
                out.nodes.resize(total);  // not filled: place() writes every node once
            } catch (...) {
                error = std::current_exception();
            }
            if (!error) place(plan, bvh, 0, 0, plan.parallel(), out);
        }
    }
    if (error) std::rethrow_exception(error);
    if (plan.oversize_leaf())
        throw std::invalid_argument("wide BVH leaves hold at most " + std::to_string(kMaxWideLeafCount) +
                                    " primitives (BvhBuildParams::max_leaf_size)");
    if (total > BvhWide<N>::kMaxNodes)
        throw InputError("scene too large: its wide BVH has " + std::to_string(total) + " nodes, more than the " +
                         std::to_string(BvhWide<N>::kMaxNodes) + " that 32-bit node offsets reach");
    return out;
}

template Bvh8 make_bvh_wide<8>(const Bvh& bvh, const WideCollapse& opt);

}  // namespace sahara
