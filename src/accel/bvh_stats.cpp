#include "accel/bvh_stats.h"

#include <algorithm>

namespace sahara {

namespace {

struct StackItem {
    uint32_t node;
    int depth;
};

template <int N>
WideBvhStats wide_stats(const BvhWide<N>& bvh, uint32_t block_size) {
    WideBvhStats s;
    s.nodes = bvh.nodes.size();
    if (bvh.empty || bvh.nodes.empty()) return s;
    auto child_box = [](const BvhWideNode<N>& n, int c) {
        return Bounds3{Vec3(n.lo_x[c], n.lo_y[c], n.lo_z[c]), Vec3(n.hi_x[c], n.hi_y[c], n.hi_z[c])};
    };
    const double root_area = bvh.root.box().surface_area();
    const double inv_root = root_area > 0 ? 1.0 / root_area : 0.0;
    for (const BvhWideNode<N>& n : bvh.nodes) {
        Bounds3 node_box;
        for (int c = 0; c < N; ++c) {
            if (!n.has_child(c)) continue;
            const Bounds3 b = child_box(n, c);
            node_box.extend(b);
            ++s.children;
            const uint32_t count = n.leaf_count(c);
            if (!count) continue;
            const size_t blocks = (count + block_size - 1) / block_size;
            ++s.leaves;
            s.leaf_primitives += count;
            s.leaf_blocks += blocks;
            s.sah_leaves += double(b.surface_area()) * double(blocks) * inv_root;
        }
        s.sah_nodes += double(node_box.surface_area()) * inv_root;
    }
    return s;
}

}  // namespace

WideBvhStats compute_wide_bvh_stats(const Bvh8& bvh, uint32_t block_size) {
    return wide_stats(bvh, std::max(block_size, 1u));
}

BvhStats compute_bvh_stats(const Bvh& bvh, const BvhBuildParams& params) {
    BvhStats s;
    s.primitives = bvh.prim_indices.size();
    s.bytes = bvh.bytes();
    if (bvh.empty()) return s;
    const double root_area = bvh.nodes[0].box().surface_area();
    const double inv_root = root_area > 0 ? 1.0 / root_area : 0.0;
    double depth_sum = 0;
    std::vector<StackItem> stack{{0, 0}};
    while (!stack.empty()) {
        const StackItem it = stack.back();
        stack.pop_back();
        const BvhNode& n = bvh.nodes[it.node];
        ++s.nodes;
        const double rel_area = double(n.box().surface_area()) * inv_root;
        s.max_depth = std::max(s.max_depth, it.depth);
        if (n.is_leaf()) {
            ++s.leaves;
            depth_sum += it.depth;
            if (s.leaf_size_histogram.size() <= n.count) s.leaf_size_histogram.resize(n.count + 1);
            ++s.leaf_size_histogram[n.count];
            s.sah_cost += double(params.intersection_cost) * n.count * rel_area;
        } else {
            s.sah_cost += double(params.traversal_cost) * rel_area;
            stack.push_back({n.index, it.depth + 1});
            stack.push_back({n.index + 1, it.depth + 1});
        }
    }
    s.mean_leaf_depth = s.leaves ? depth_sum / double(s.leaves) : 0.0;
    return s;
}

std::string validate_bvh(const Bvh& bvh, std::span<const Bounds3> prim_boxes) {
    const size_t n = prim_boxes.size();
    if (bvh.prim_indices.size() != n) return "slot count differs from primitive count";
    if (n == 0) return bvh.nodes.empty() ? "" : "nodes without primitives";
    if (bvh.nodes.empty()) return "no nodes";
    std::vector<int> slot_seen(n, 0), prim_seen(n, 0), node_seen(bvh.nodes.size(), 0);
    std::vector<StackItem> stack{{0, 0}};
    while (!stack.empty()) {
        const StackItem it = stack.back();
        stack.pop_back();
        if (it.node >= bvh.nodes.size()) return "child index out of range";
        if (node_seen[it.node]++) return "node " + std::to_string(it.node) + " reached twice";
        if (it.depth >= kBvhMaxDepth) return "depth exceeds kBvhMaxDepth";
        const BvhNode& node = bvh.nodes[it.node];
        const Bounds3 box = node.box();
        if (node.is_leaf()) {
            if (size_t(node.index) + node.count > n) return "leaf range out of range";
            for (uint32_t s = node.index; s < node.index + node.count; ++s) {
                const uint32_t p = bvh.prim_indices[s];
                if (p >= n) return "primitive index out of range";
                ++slot_seen[s];
                ++prim_seen[p];
                if (!prim_boxes[p].empty() && !box.contains(prim_boxes[p]))
                    return "leaf " + std::to_string(it.node) + " does not contain primitive " +
                           std::to_string(p);
            }
            continue;
        }
        if (node.index % 2 != 0) return "sibling pair at odd index " + std::to_string(node.index);
        for (uint32_t c = node.index; c < node.index + 2; ++c) {
            if (c >= bvh.nodes.size()) return "child index out of range";
            const Bounds3 child = bvh.nodes[c].box();
            if (!child.empty() && !box.contains(child))
                return "child " + std::to_string(c) + " not inside parent " + std::to_string(it.node);
            stack.push_back({c, it.depth + 1});
        }
    }
    for (size_t i = 0; i < n; ++i) {
        if (slot_seen[i] != 1)
            return "slot " + std::to_string(i) + " in " + std::to_string(slot_seen[i]) + " leaves";
        if (prim_seen[i] != 1)
            return "primitive " + std::to_string(i) + " in " + std::to_string(prim_seen[i]) + " leaves";
    }
    for (size_t i = 0; i < node_seen.size(); ++i)
        if (!node_seen[i] && i != 1) return "node " + std::to_string(i) + " unreachable";
    return "";
}

}  // namespace sahara
