#include "accel/bvh_pairs.h"

namespace sahara {

namespace {

void set_child(BvhPairNode& p, int c, const BvhNode& child) {
    p.x[c] = child.bounds[0];
    p.x[c + 2] = child.bounds[1];
    p.y[c] = child.bounds[2];
    p.y[c + 2] = child.bounds[3];
    p.z[c] = child.bounds[4];
    p.z[c + 2] = child.bounds[5];
    p.count[c] = child.count;
    p.index[c] = child.count ? child.index : kNoNode;  // inner: patched when the child's pair is placed
}

}  // namespace

BvhPairs make_bvh_pairs(const Bvh& bvh) {
    BvhPairs out;
    if (bvh.empty()) return out;
    out.empty = false;
    out.root = bvh.nodes[0];
    if (out.root.is_leaf()) return out;
    out.nodes.reserve(bvh.nodes.size() / 2);
    // Depth-first: (canonical inner node, pair slot that must point at it, child side).
    struct Pending {
        uint32_t node;
        uint32_t parent_pair;
        int side;
    };
    std::vector<Pending> stack{{0, kNoNode, 0}};
    while (!stack.empty()) {
        const Pending it = stack.back();
        stack.pop_back();
        const auto pair = uint32_t(out.nodes.size());
        if (it.parent_pair != kNoNode) out.nodes[it.parent_pair].index[it.side] = pair;
        const BvhNode& n = bvh.nodes[it.node];
        BvhPairNode p{};
        for (int c = 0; c < 2; ++c) set_child(p, c, bvh.nodes[n.index + uint32_t(c)]);
        out.nodes.push_back(p);
        // Push the right child first so the left subtree follows its parent in memory.
        for (int c = 1; c >= 0; --c)
            if (!bvh.nodes[n.index + uint32_t(c)].is_leaf())
                stack.push_back({n.index + uint32_t(c), pair, c});
    }
    return out;
}

}  // namespace sahara
