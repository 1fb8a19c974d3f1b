#include "accel/bvh_wide.h"

#include <array>
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

/// Which binary-tree nodes become the children of each N-wide node. The leaves
/// stay as built, so the SAH cost of the wide tree varies only in its node term:
/// the summed surface area of the wide nodes (the expected number of node visits
/// of a random ray, up to the root's area). A dynamic programme over the binary
/// tree minimises that sum exactly (the collapse step of Ylitie, Karras and
/// Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
/// BVHs", 2017, with the leaves fixed); the usual greedy rule, opening the
/// largest inner child until N are gathered, gave 2-4% more (`sahara bvh`).
template <int N>
class CollapsePlan {
   public:
    explicit CollapsePlan(const Bvh& bvh) : bvh_(bvh), cost_(bvh.nodes.size()), plan_(bvh.nodes.size()) {
        // Children follow their parent in the canonical (depth-first) order.
        for (size_t x = bvh.nodes.size(); x-- > 0;) {
            const BvhNode& node = bvh.nodes[x];
            Costs& f = cost_[x];
            if (node.is_leaf()) {
                f.fill(0.0);
                continue;
            }
            const Costs& left = cost_[node.index];
            const Costs& right = cost_[node.index + 1];
            // opened[k]: both children share k slots of the parent's node.
            Costs opened;
            opened.fill(std::numeric_limits<double>::infinity());
            for (int k = 2; k <= N; ++k)
                for (int j = 1; j < k; ++j)
                    if (left[j] + right[k - j] < opened[k]) {
                        opened[k] = left[j] + right[k - j];
                        plan_[x].left_slots[k] = uint8_t(j);
                    }
            // Kept as one child, x is a node of its own: its area plus its children in N slots.
            const double as_node = double(half_area(node)) + opened[N];
            f[1] = as_node;
            for (int k = 2; k <= N; ++k) {
                plan_[x].open[k] = opened[k] < as_node;
                f[k] = plan_[x].open[k] ? opened[k] : as_node;
            }
        }
    }

    /// The children of the N-wide node made for binary inner node `inner`.
    int children(uint32_t inner, uint32_t out[N]) const {
        int n = 0;
        const uint32_t first = bvh_.nodes[inner].index;
        const int j = plan_[inner].left_slots[N];
        emit(first, j, out, n);
        emit(first + 1, N - j, out, n);
        return n;
    }

   private:
    using Costs = std::array<double, N + 1>;  ///< [k]: least node area of a subtree in k slots
    struct Choice {
        std::array<uint8_t, N + 1> left_slots{};  ///< [k]: slots of the left child when opened
        std::array<bool, N + 1> open{};           ///< [k]: opened into k slots, or kept as one child
    };

    void emit(uint32_t x, int k, uint32_t out[N], int& n) const {
        if (bvh_.nodes[x].is_leaf() || !plan_[x].open[k]) {
            out[n++] = x;
            return;
        }
        const int j = plan_[x].left_slots[k];
        emit(bvh_.nodes[x].index, j, out, n);
        emit(bvh_.nodes[x].index + 1, k - j, out, n);
    }

    const Bvh& bvh_;
    std::vector<Costs> cost_;
    std::vector<Choice> plan_;
};

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
    const CollapsePlan<N> plan(bvh);
    std::vector<Pending> stack{{0, kNoNode, 0}};
    while (!stack.empty()) {
        const Pending it = stack.back();
        stack.pop_back();
        const auto index = uint32_t(out.nodes.size());
        if (it.parent != kNoNode) out.nodes[it.parent].child[it.slot] = index;
        uint32_t kids[N];
        const int n = plan.children(it.node, kids);
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
