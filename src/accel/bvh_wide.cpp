#include "accel/bvh_wide.h"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace sahara {

namespace {

float half_area(const BvhNode& n) {
    const float dx = n.bounds[1] - n.bounds[0], dy = n.bounds[3] - n.bounds[2],
                dz = n.bounds[5] - n.bounds[4];
    return dx < 0.0f ? 0.0f : dx * dy + dy * dz + dz * dx;
}

/// Up to N binary-tree nodes that become the children of one N-wide node:
/// starting from the two children of `inner`, the inner child with the largest
/// surface area is replaced by its two children until there are N.
template <int N>
int gather_children(const Bvh& bvh, uint32_t inner, uint32_t out[N]) {
    int n = 2;
    out[0] = bvh.nodes[inner].index;
    out[1] = bvh.nodes[inner].index + 1;
    while (n < N) {
        int best = -1;
        float best_area = -1.0f;
        for (int i = 0; i < n; ++i) {
            const BvhNode& c = bvh.nodes[out[i]];
            if (!c.is_leaf() && half_area(c) > best_area) best = i, best_area = half_area(c);
        }
        if (best < 0) break;
        const uint32_t first = bvh.nodes[out[best]].index;
        out[best] = first;
        out[n++] = first + 1;
    }
    return n;
}

template <int N>
void set_child(BvhWideNode<N>& p, int c, const BvhNode& child) {
    p.lo_x[c] = child.bounds[0];
    p.hi_x[c] = child.bounds[1];
    p.lo_y[c] = child.bounds[2];
    p.hi_y[c] = child.bounds[3];
    p.lo_z[c] = child.bounds[4];
    p.hi_z[c] = child.bounds[5];
    p.count[c] = child.count;
    p.child[c] = child.count ? child.index : kNoNode;  // inner: patched when its node is placed
}

template <int N>
BvhWideNode<N> empty_node() {
    BvhWideNode<N> p{};
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (int c = 0; c < N; ++c) {
        p.lo_x[c] = p.lo_y[c] = p.lo_z[c] = inf;
        p.hi_x[c] = p.hi_y[c] = p.hi_z[c] = -inf;
        p.child[c] = kNoNode;
        p.count[c] = 0;
    }
    return p;
}

}  // namespace

template <int N>
BvhWide<N> make_bvh_wide(const Bvh& bvh) {
    BvhWide<N> out;
    if (bvh.empty()) return out;
    out.empty = false;
    out.root = bvh.nodes[0];
    if (out.root.is_leaf()) return out;
    out.nodes.reserve(bvh.nodes.size() / (N - 1) + 1);
    // Depth-first: (canonical inner node, wide node that must point at it, child slot).
    struct Pending {
        uint32_t node;
        uint32_t parent;
        int slot;
    };
    std::vector<Pending> stack{{0, kNoNode, 0}};
    while (!stack.empty()) {
        const Pending it = stack.back();
        stack.pop_back();
        const auto index = uint32_t(out.nodes.size());
        if (it.parent != kNoNode) out.nodes[it.parent].child[it.slot] = index;
        uint32_t kids[N];
        const int n = gather_children<N>(bvh, it.node, kids);
        BvhWideNode<N> p = empty_node<N>();
        for (int c = 0; c < n; ++c) set_child(p, c, bvh.nodes[kids[c]]);
        out.nodes.push_back(p);
        for (int c = n - 1; c >= 0; --c)
            if (!bvh.nodes[kids[c]].is_leaf()) stack.push_back({kids[c], index, c});
    }
    return out;
}

template Bvh4 make_bvh_wide<4>(const Bvh& bvh);
template Bvh8 make_bvh_wide<8>(const Bvh& bvh);

bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

bool cpu_has_avx512() {
#if defined(__x86_64__) || defined(__i386__)
    return cpu_has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#else
    return false;
#endif
}

SimdPath best_simd_path() {
    return cpu_has_avx512() ? SimdPath::avx512 : cpu_has_avx2() ? SimdPath::avx2 : SimdPath::sse2;
}

namespace {

/// `want`, or the widest path below it that this CPU runs.
SimdPath supported(SimdPath want) {
    if (want == SimdPath::avx512 && !cpu_has_avx512()) want = SimdPath::avx2;
    if (want == SimdPath::avx2 && !cpu_has_avx2()) want = SimdPath::sse2;
    return want;
}

}  // namespace

std::vector<SimdPath> runnable_simd_paths() {
    std::vector<SimdPath> paths{SimdPath::sse2};
    if (cpu_has_avx2()) paths.push_back(SimdPath::avx2);
    if (cpu_has_avx512()) paths.push_back(SimdPath::avx512);
    return paths;
}

namespace detail {
std::atomic<int> g_simd_path{-1};
}  // namespace detail

SimdPath init_simd_path() {
    static const SimdPath from_env = [] {
        const char* env = std::getenv("SAHARA_SIMD");
        if (env && std::strcmp(env, "sse2") == 0) return SimdPath::sse2;
        if (env && std::strcmp(env, "avx2") == 0) return supported(SimdPath::avx2);
        return best_simd_path();
    }();
    int expected = -1;
    detail::g_simd_path.compare_exchange_strong(expected, int(from_env), std::memory_order_relaxed);
    return SimdPath(detail::g_simd_path.load(std::memory_order_relaxed));
}

void force_simd_path(SimdPath path) {
    detail::g_simd_path.store(int(supported(path)), std::memory_order_relaxed);
}

const char* simd_path_name(SimdPath path) {
    return path == SimdPath::avx512 ? "avx512" : path == SimdPath::avx2 ? "avx2" : "sse2";
}

}  // namespace sahara
