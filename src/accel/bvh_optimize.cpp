/// Post-build optimisation of a binary BVH by insertion-based reinsertion
/// (Bittner, Hapala and Havran, "Fast Insertion-Based Optimization of Bounding
/// Volume Hierarchies", 2013), followed by an SAH-optimal collapse of subtrees
/// into leaves.
///
/// The tree is first expanded to one primitive per leaf (one reference per
/// primitive throughout). Each round picks the inner nodes with the largest
/// inefficiency measure M = M_sum * M_min * M_area of the paper, removes each
/// such node N together with its parent (N's sibling takes the parent's place)
/// and reinserts N's two children, each at the position that minimises the
/// SAH cost increase, found by the paper's branch-and-bound search over the
/// tree (a priority queue ordered by the induced cost of the ancestors).
/// Rounds stop when the SAH cost stops falling. Finally each subtree becomes a
/// leaf where that is cheaper than keeping it (bottom-up, exact for the given
/// topology), and the tree is written out in the Bvh sibling-pair layout. That
/// last step weights up leaves that hold a primitive spanning much of the scene
/// (BvhBuildParams::large_leaf_area_share), which rays from inside it cross often.
#include <algorithm>
#include <array>
#include <cmath>
#include <queue>
#include <utility>
#include <vector>

#include "accel/bvh.h"

namespace sahara {

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;

/// Area used for all costs: half the surface area (the SAH only needs ratios); 0 for empty boxes.
double area(const Bounds3& b) { return 0.5 * double(b.surface_area()); }

/// A pointer-linked binary tree with parent links and one primitive per leaf.
class LinkedTree {
   public:
    LinkedTree(const Bvh& bvh, std::span<const Bounds3> prim_boxes) : prim_boxes_(prim_boxes) {
        const size_t n = bvh.prim_indices.size();
        box_.reserve(2 * n);
        parent_.reserve(2 * n);
        child_.reserve(2 * n);
        prim_.reserve(2 * n);
        root_ = convert(bvh, 0, kNone);
    }

    uint32_t root() const { return root_; }
    size_t size() const { return box_.size(); }
    bool is_leaf(uint32_t n) const { return child_[n][0] == kNone; }
    const Bounds3& box(uint32_t n) const { return box_[n]; }
    uint32_t child(uint32_t n, int c) const { return child_[n][c]; }
    uint32_t prim(uint32_t n) const { return prim_[n]; }
    uint32_t parent(uint32_t n) const { return parent_[n]; }

    /// Sum over inner nodes of traversal * A plus over leaves of intersection * A (one primitive each).
    double sah(double traversal, double intersection) const {
        double cost = 0;
        for (uint32_t n = 0; n < size(); ++n)
            if (parent_[n] != kNone || n == root_)
                cost += area(box_[n]) * (is_leaf(n) ? intersection : traversal);
        return cost;
    }

    /// Depth of the deepest leaf (root = 0).
    int max_depth() const {
        int deepest = 0;
        std::vector<std::pair<uint32_t, int>> stack{{root_, 0}};
        while (!stack.empty()) {
            const auto [n, d] = stack.back();
            stack.pop_back();
            deepest = std::max(deepest, d);
            if (!is_leaf(n)) stack.push_back({child_[n][0], d + 1}), stack.push_back({child_[n][1], d + 1});
        }
        return deepest;
    }

    /// One round of the paper: removes and reinserts the `count` most inefficient inner nodes.
    void reinsert_round(size_t count) {
        std::vector<std::pair<double, uint32_t>> candidates;
        for (uint32_t n = 0; n < size(); ++n) {
            if (is_leaf(n) || n == root_ || parent_[n] == root_) continue;
            candidates.push_back({-inefficiency(n), n});
        }
        count = std::min(count, candidates.size());
        std::partial_sort(candidates.begin(), candidates.begin() + ptrdiff_t(count), candidates.end());
        for (size_t i = 0; i < count; ++i) {
            const uint32_t n = candidates[i].second;
            // An earlier reinsertion of this round may have moved n next to the root.
            if (n == root_ || parent_[n] == root_) continue;
            reinsert(n);
        }
    }

   private:
    uint32_t add_node(const Bounds3& box, uint32_t parent, uint32_t prim) {
        box_.push_back(box);
        parent_.push_back(parent);
        child_.push_back({kNone, kNone});
        prim_.push_back(prim);
        return uint32_t(box_.size() - 1);
    }

    /// Copies the subtree at bvh node `src`; a leaf of several primitives becomes a balanced subtree.
    uint32_t convert(const Bvh& bvh, uint32_t src, uint32_t parent) {
        const BvhNode& node = bvh.nodes[src];
        if (node.is_leaf()) return convert_slots(bvh, node.index, node.index + node.count, parent);
        const uint32_t id = add_node(node.box(), parent, kNone);
        for (int c = 0; c < 2; ++c) child_[id][c] = convert(bvh, node.index + uint32_t(c), id);
        return id;
    }

    uint32_t convert_slots(const Bvh& bvh, uint32_t begin, uint32_t end, uint32_t parent) {
        if (end - begin == 1) {
            const uint32_t p = bvh.prim_indices[begin];
            return add_node(prim_boxes_[p], parent, p);
        }
        const uint32_t id = add_node(Bounds3{}, parent, kNone);
        const uint32_t mid = begin + (end - begin) / 2;
        child_[id][0] = convert_slots(bvh, begin, mid, id);
        child_[id][1] = convert_slots(bvh, mid, end, id);
        box_[id] = join(box_[child_[id][0]], box_[child_[id][1]]);
        return id;
    }

    /// M_sum * M_min * M_area of Bittner et al.: large for big nodes whose children are small.
    double inefficiency(uint32_t n) const {
        const double a = area(box_[n]);
        const double a0 = area(box_[child_[n][0]]), a1 = area(box_[child_[n][1]]);
        const double tiny = 1e-30;
        return a * (a / std::max(0.5 * (a0 + a1), tiny)) * (a / std::max(std::min(a0, a1), tiny));
    }

    /// Recomputes the boxes from `n` up to the root; returns the change of their summed area.
    double refit_up(uint32_t n) {
        double growth = 0;
        for (; n != kNone; n = parent_[n]) {
            const double old_area = area(box_[n]);
            box_[n] = join(box_[child_[n][0]], box_[child_[n][1]]);
            growth += area(box_[n]) - old_area;
        }
        return growth;
    }

    void replace_child(uint32_t parent, uint32_t old_child, uint32_t new_child) {
        if (parent == kNone) {
            root_ = new_child;
        } else {
            auto& c = child_[parent];
            (c[0] == old_child ? c[0] : c[1]) = new_child;
        }
        parent_[new_child] = parent;
    }

    /// Unlinks subtree x and its parent (x's sibling takes the parent's place).
    void detach(uint32_t x) {
        const uint32_t p = parent_[x];
        const uint32_t sibling = child_[p][0] == x ? child_[p][1] : child_[p][0];
        const uint32_t g = parent_[p];
        replace_child(g, p, sibling);
        refit_up(g);
    }

    /// Removes inner node n and its parent, then reinserts n's children (larger area first),
    /// reusing n and its parent as the two new inner nodes. Moves that do not lower the SAH
    /// cost (the children's greedy insertions can end up worse than where they were) are undone,
    /// so the cost never rises. Returns the change of the summed inner-node area.
    double reinsert(uint32_t n) {
        const uint32_t p = parent_[n];
        const uint32_t g = parent_[p];
        const std::array<uint32_t, 2> kids = child_[n], p_kids = child_[p];
        const uint32_t sibling = p_kids[0] == n ? p_kids[1] : p_kids[0];
        const double removed = area(box_[n]) + area(box_[p]);
        replace_child(g, p, sibling);
        double delta = refit_up(g) - removed;
        uint32_t a = kids[0], b = kids[1];
        if (area(box_[a]) < area(box_[b])) std::swap(a, b);
        delta += insert(a, n);
        delta += insert(b, p);
        if (delta < 0) return delta;
        detach(b);
        detach(a);
        child_[n] = kids;
        parent_[kids[0]] = parent_[kids[1]] = n;
        child_[p] = p_kids;
        parent_[n] = parent_[sibling] = p;
        replace_child(g, sibling, p);
        refit_up(n);
        return 0;
    }

    /// Inserts subtree x as the sibling of the best node, with `fresh` as their new parent;
    /// returns the growth of the summed inner-node area (the new node included).
    double insert(uint32_t x, uint32_t fresh) {
        const uint32_t target = best_sibling(x);
        const uint32_t above = parent_[target];
        replace_child(above, target, fresh);
        child_[fresh] = {target, x};
        parent_[target] = fresh;
        parent_[x] = fresh;
        box_[fresh] = Bounds3{};
        return refit_up(fresh);
    }

    /// The paper's branch-and-bound search: the node y minimising the cost of
    /// making x its sibling, A(x u y) plus the growth of every ancestor of y.
    uint32_t best_sibling(uint32_t x) {
        const Bounds3& bx = box_[x];
        const double ax = area(bx);
        uint32_t best = root_;
        double best_cost = kInfinity;
        queue_ = {};
        queue_.push({0.0, root_});
        while (!queue_.empty()) {
            const auto [neg_induced, y] = queue_.top();
            const double induced = -neg_induced;
            queue_.pop();
            if (induced + ax >= best_cost) break;  // every remaining candidate costs at least this
            const double direct = area(join(box_[y], bx));
            const double cost = induced + direct;
            if (cost < best_cost) best_cost = cost, best = y;
            if (is_leaf(y)) continue;
            const double child_induced = cost - area(box_[y]);
            if (child_induced + ax >= best_cost) continue;
            queue_.push({-child_induced, child_[y][0]});
            queue_.push({-child_induced, child_[y][1]});
        }
        return best;
    }

    std::span<const Bounds3> prim_boxes_;
    std::vector<Bounds3> box_;
    std::vector<uint32_t> parent_;
    std::vector<std::array<uint32_t, 2>> child_;
    std::vector<uint32_t> prim_;  ///< leaves: the primitive
    uint32_t root_ = kNone;
    std::priority_queue<std::pair<double, uint32_t>> queue_;  ///< (-induced cost, node), smallest first
};

/// Bottom-up SAH collapse and output in the sibling-pair layout.
class Collapser {
   public:
    Collapser(const LinkedTree& tree, const BvhBuildParams& params) : tree_(tree), params_(params) {
        count_.assign(tree.size(), 0);
        cost_.assign(tree.size(), 0.0);
        make_leaf_.assign(tree.size(), 0);
        large_.assign(tree.size(), 0);
        large_area_ = double(params.large_leaf_area_share) * area(tree.box(tree.root()));
        large_factor_ = std::max(1.0, double(params.large_leaf_cost_factor));
        // Post-order by reversing a pre-order walk: children before parents.
        std::vector<uint32_t> order, stack{tree.root()};
        while (!stack.empty()) {
            const uint32_t n = stack.back();
            stack.pop_back();
            order.push_back(n);
            if (!tree.is_leaf(n)) stack.push_back(tree.child(n, 0)), stack.push_back(tree.child(n, 1));
        }
        for (auto it = order.rbegin(); it != order.rend(); ++it) evaluate(*it);
    }

    /// SAH cost of the collapsed tree (unnormalised: sum of areas times costs).
    double cost() const { return cost_[tree_.root()]; }

    Bvh emit() const {
        Bvh out;
        out.prim_indices.reserve(count_[tree_.root()]);
        out.nodes.resize(1);
        if (!make_leaf_[tree_.root()]) {
            out.nodes.resize(2);
            out.nodes[1] = BvhNode{{0, 0, 0, 0, 0, 0}, 0, 0};  // padding (resize does not fill)
        }
        std::vector<std::pair<uint32_t, uint32_t>> stack{{tree_.root(), 0}};  // (tree node, output node)
        while (!stack.empty()) {
            const auto [n, slot] = stack.back();
            stack.pop_back();
            BvhNode node{};
            node.set_box(tree_.box(n));
            if (make_leaf_[n]) {
                node.index = uint32_t(out.prim_indices.size());
                node.count = count_[n];
                gather(n, out.prim_indices);
            } else {
                node.index = uint32_t(out.nodes.size());
                node.count = 0;
                out.nodes.resize(out.nodes.size() + 2);
                stack.push_back({tree_.child(n, 1), node.index + 1});
                stack.push_back({tree_.child(n, 0), node.index});
            }
            out.nodes[slot] = node;
        }
        return out;
    }

   private:
    void evaluate(uint32_t n) {
        const double a = area(tree_.box(n));
        const double ci = double(params_.intersection_cost), ct = double(params_.traversal_cost);
        if (tree_.is_leaf(n)) {
            count_[n] = 1;
            large_[n] = large_area_ > 0 && a >= large_area_;
            cost_[n] = ci * blocked(1) * a;
            make_leaf_[n] = 1;
            return;
        }
        const uint32_t c0 = tree_.child(n, 0), c1 = tree_.child(n, 1);
        count_[n] = count_[c0] + count_[c1];
        large_[n] = large_[c0] | large_[c1];
        const double split = ct * a + cost_[c0] + cost_[c1];
        const double leaf = ci * (large_[n] ? large_factor_ : 1.0) * blocked(count_[n]) * a;
        make_leaf_[n] = count_[n] <= params_.max_leaf_size && leaf <= split;
        cost_[n] = make_leaf_[n] ? leaf : split;
    }

    /// Primitives a leaf of n tests: whole blocks of params_.leaf_block_size (as the
    /// binned builder counts them), so leaves fill the block layouts' blocks.
    double blocked(uint32_t n) const {
        const uint32_t b = std::max(params_.leaf_block_size, 1u);
        return double((n + b - 1) / b * b);
    }

    void gather(uint32_t n, std::vector<uint32_t>& out) const {
        if (tree_.is_leaf(n)) {
            out.push_back(tree_.prim(n));
            return;
        }
        gather(tree_.child(n, 0), out);
        gather(tree_.child(n, 1), out);
    }

    const LinkedTree& tree_;
    const BvhBuildParams& params_;
    std::vector<uint32_t> count_;
    std::vector<double> cost_;
    std::vector<uint8_t> make_leaf_;
    std::vector<uint8_t> large_;  ///< the subtree holds a primitive of large_area_ or more
    double large_area_ = 0;
    double large_factor_ = 1;
};

}  // namespace

Bvh reinsert_optimize_bvh(const Bvh& bvh, std::span<const Bounds3> prim_boxes, const BvhBuildParams& params) {
    if (bvh.empty()) return bvh;
    LinkedTree tree(bvh, prim_boxes);
    // The input collapsed by SAH: never worse than the input, and the fallback.
    const Collapser input_collapse(tree, params);
    const double before_cost = input_collapse.cost();
    Bvh before = input_collapse.emit();
    const double ct = double(params.traversal_cost), ci = double(params.intersection_cost);
    // Single-primitive leaves: the cost the reinsertion rounds minimise (the paper's SAH).
    double cost = tree.sah(ct, ci);
    const size_t inner = tree.size() / 2;
    const auto batch = size_t(std::max(1.0, double(inner) * double(params.reinsert_batch_fraction)));
    int stalled = 0;
    for (uint32_t round = 0; round < params.reinsert_max_rounds && stalled < 2; ++round) {
        tree.reinsert_round(batch);
        const double next = tree.sah(ct, ci);
        // Stop once two rounds in a row no longer reduce the cost noticeably.
        stalled = next > cost * (1.0 - double(params.reinsert_min_gain)) ? stalled + 1 : 0;
        cost = std::min(cost, next);
    }
    const Collapser after(tree, params);
    // Keep the result only when it is better and shallow enough for traversal stacks.
    const bool better = after.cost() < before_cost;
    if (better && tree.max_depth() < kBvhMaxDepth - 4) return after.emit();
    return before;
}

}  // namespace sahara
