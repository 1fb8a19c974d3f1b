#pragma once
/// The cheap result of a ray-primitive test (20 bytes). Rich surface data is
/// computed once, for the accepted hit only (see scene/scene.h).
#include <cstdint>

#include "math/ray.h"

namespace sahara {

inline constexpr uint32_t kNoPrim = 0xFFFFFFFFu;
/// Hit::instance of a hit on geometry that is not instanced.
inline constexpr uint32_t kNoInstance = 0xFFFFFFFFu;

/// Primitive ids carry their kind in the top three bits so that a leaf can hold
/// mixed primitives and dispatch with a switch (no virtual call per test); the
/// other 29 bits index the kind's array (up to 536M primitives per kind).
enum class PrimKind : uint32_t { triangle = 0, sphere = 1, box = 2, plane = 3, quadric = 4 };
inline constexpr int kPrimKindShift = 29;
inline constexpr uint32_t kPrimIndexMask = (1u << kPrimKindShift) - 1u;
constexpr uint32_t make_prim_id(PrimKind kind, uint32_t index) {
    return (uint32_t(kind) << kPrimKindShift) | index;
}
constexpr PrimKind prim_kind(uint32_t id) { return PrimKind(id >> kPrimKindShift); }
constexpr uint32_t prim_index(uint32_t id) { return id & kPrimIndexMask; }

struct Hit {
    float t = kInfinity;
    uint32_t prim = kNoPrim;  ///< made by make_prim_id; kNoPrim = miss
    float u = 0, v = 0;       ///< triangle barycentrics (of v1, v2); unused by spheres
    /// The instance whose prototype holds `prim` (scene/instances.h); kNoInstance for
    /// the scene's own primitives. Only the instance level writes it.
    uint32_t instance = kNoInstance;
    bool hit() const { return prim != kNoPrim; }
};
static_assert(sizeof(Hit) == 20);

/// What stopped the last occlusion ray of one light on one thread: a shadow cache
/// (Haines and Greenberg, "The Light Buffer", 1986, reduced to one entry). The next ray
/// tests that leaf block first and skips the traversal when it still blocks, as it
/// mostly does for neighbouring shading points. The answer is exactly the traversal's:
/// the block goes through the same leaf test (cut-outs and one-sided triangles
/// included), and any primitive that blocks the ray makes it occluded.
struct OcclusionCache {
    /// The Accelerator (scene/accelerator.h) that filled it; another one ignores it.
    const void* owner = nullptr;
    uint32_t block = 0;  ///< the occluder's leaf block (wide8 layout)
};

}  // namespace sahara
