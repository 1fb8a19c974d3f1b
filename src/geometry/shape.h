#pragma once
/// The contract every shape meets: sphere, triangle (TriangleVerts), box,
/// quadric and plane. A shape states whether it is bounded (bounded shapes sit
/// in the BVH; unbounded ones, planes, are tested beside it), gives its bounds,
/// and answers two ray queries over the open interval (ray.tmin, ray.tmax):
/// intersect() the nearest hit, occluded() whether there is any. Each shape
/// header checks itself with static_assert(Shape<...>).
///
/// The accelerator calls these members directly, dispatching on the kind tag in
/// the primitive id (geometry/hit.h) with a switch: no virtual call and no
/// allocation per ray-primitive test.
#include <concepts>
#include <cstdint>
#include <optional>

#include "math/bounds.h"
#include "math/ray.h"

namespace sahara {

/// A ray-shape hit; every shape fills the same fields.
struct ShapeHit {
    float t = kInfinity;  ///< ray parameter in units of |ray.dir|, inside (ray.tmin, ray.tmax)
    float u = 0, v = 0;   ///< triangles: barycentric weights of vertices 1 and 2; 0 otherwise
    uint32_t part = 0;    ///< which part was hit, for shapes made of parts (QuadricPart); else 0
};

template <class S>
concept Shape = requires(const S& shape, const Ray& ray) {
    /// Whether bounds() is a finite box the BVH can hold (false: the shape is infinite).
    { S::kBounded } -> std::convertible_to<bool>;
    { shape.bounds() } -> std::same_as<Bounds3>;
    /// Nearest hit in (ray.tmin, ray.tmax), or nullopt.
    { shape.intersect(ray) } -> std::same_as<std::optional<ShapeHit>>;
    /// Whether intersect(ray) would hit (it may stop at the first hit it finds).
    { shape.occluded(ray) } -> std::same_as<bool>;
};

/// The box of all space: the bounds of an unbounded shape.
inline Bounds3 unbounded_bounds() { return Bounds3{Vec3(-kInfinity), Vec3(kInfinity)}; }

}  // namespace sahara
