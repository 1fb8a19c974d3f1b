#pragma once
/// Quadric surfaces: the implicit f(x,y,z) = A x² + B y² + C z² + D xy + E xz +
/// F yz + G x + H y + I z + J = 0, clipped so that each one is bounded and can
/// sit in a BVH. Named forms (ellipsoid, cylinder, cone, paraboloid, one-sheet
/// hyperboloid) are stored in a canonical object frame where they are unit-sized
/// and aligned with +z; world_from_object carries position, orientation and
/// size. A ray is mapped into that frame and solved there in double.
///
/// Canonical forms (object frame):
///   ellipsoid    x² + y² + z² - 1 = 0                 (no clipping)
///   cylinder     x² + y² - 1 = 0,          0 <= z <= 1 (caps: disks at z = 0 and z = 1)
///   cone         x² + y² - z² = 0,         0 <= z <= 1 (apex at 0; cap: disk at z = 1)
///   paraboloid   x² + y² - z = 0,          z <= 1
///   hyperboloid  x² + y² - k z² - 1 = 0,   -1 <= z <= 1 (k = (radius/waist)² - 1)
///   general      the given coefficients inside the given box
/// The outward side is where f > 0 (the gradient direction); caps face away
/// from the body. Both sides are hit; surface() reports which side was hit.
#include <array>
#include <cstdint>
#include <limits>
#include <optional>

#include "geometry/shape.h"
#include "math/bounds.h"
#include "math/ray.h"
#include "math/transform.h"

namespace sahara {

enum class QuadricForm : uint8_t { ellipsoid, cylinder, cone, paraboloid, hyperboloid, general };

/// The part of a quadric a ray hit: the curved surface or one of the cap disks.
enum class QuadricPart : uint8_t { side = 0, bottom_cap = 1, top_cap = 2 };

/// Shading-independent data at an accepted hit.
struct QuadricSurface {
    Vec3 p;   ///< world-space point, projected onto the surface
    Vec3 n;   ///< outward unit geometric normal (not flipped towards the ray)
    Vec2 uv;  ///< cylinder/cone/paraboloid/hyperboloid: (angle, height); ellipsoid: spherical; caps: planar
    bool front_face = true;  ///< the ray arrived from the outward side
};

struct Quadric {
    static constexpr bool kBounded = true;

    QuadricForm form = QuadricForm::general;
    /// Object-frame coefficients A..J (order as in the file comment).
    std::array<double, 10> coeffs{};
    /// Object-frame clip box: the surface exists only where clip_lo <= p <= clip_hi.
    Vec3d clip_lo{-std::numeric_limits<double>::infinity()};
    Vec3d clip_hi{std::numeric_limits<double>::infinity()};
    /// Cap disks x² + y² <= 1 at z = clip_lo.z (bottom) and z = clip_hi.z (top).
    bool cap_bottom = false, cap_top = false;
    Mat4 world_from_object, object_from_world;
    Bounds3 world_bounds;  ///< cached by finalize()
    Vec3d solve_origin;    ///< object-frame point rays are re-based to before solving (finalize())
    uint32_t material = 0;

    /// World-space bounds of the clipped surface (and caps).
    Bounds3 bounds() const { return world_bounds; }
    /// Nearest hit in (ray.tmin, ray.tmax); its part is a QuadricPart.
    std::optional<ShapeHit> intersect(const Ray& ray) const;
    bool occluded(const Ray& ray) const { return intersect(ray).has_value(); }
    /// The hit intersect() returned at distance t along `ray` (same origin and direction),
    /// its part included; for a primitive id and t kept without the part.
    ShapeHit hit_at(const Ray& ray, float t) const;
    /// Point, outward normal, UV and side for a hit returned by intersect().
    QuadricSurface surface(const Ray& ray, const ShapeHit& hit) const;
    /// Outward unit normal at a world point on (or very near) the surface;
    /// points on a cap plane inside the disk get the cap normal.
    Vec3 normal(const Vec3& p_world) const;

    /// f at an object-frame point.
    double eval(const Vec3d& p) const;
    /// Gradient of f at an object-frame point.
    Vec3d gradient(const Vec3d& p) const;
    /// Computes object_from_world, world_bounds and solve_origin from the other fields.
    void finalize();
};
static_assert(Shape<Quadric>);

// Factories. Each validates its parameters and throws InputError with a
// message such as "radius: expected a number > 0, got -1" (the scene parser
// prefixes the file and element). world_from_object is applied after the
// placement given by the parameters, as the scene format's `transform`.

/// Ellipsoid with axis-aligned radii (before world_from_object).
Quadric make_ellipsoid(const Vec3& center, const Vec3& radii, const Mat4& world_from_object = {});
/// Cylinder from base to base + height * normalize(axis); capped adds both end disks.
Quadric make_cylinder(const Vec3& base, const Vec3& axis, float radius, float height, bool capped,
                      const Mat4& world_from_object = {});
/// Single cone opening from apex along axis; angle_deg is the half-angle between
/// the axis and the surface, in (0, 90); capped adds the disk at the far end.
Quadric make_cone(const Vec3& apex, const Vec3& axis, float angle_deg, float height, bool capped,
                  const Mat4& world_from_object = {});
/// Paraboloid of revolution opening from vertex along axis, with the given radius at `height`.
Quadric make_paraboloid(const Vec3& vertex, const Vec3& axis, float radius, float height,
                        const Mat4& world_from_object = {});
/// One-sheet hyperboloid of revolution centred at `center`: `waist` is the radius at the
/// centre, `radius` the radius at both ends, `height` the full length along axis (radius >= waist).
Quadric make_hyperboloid(const Vec3& center, const Vec3& axis, float radius, float waist, float height,
                         const Mat4& world_from_object = {});
/// General quadric (coefficients A..J) restricted to the box [lo, hi], both in the object frame.
Quadric make_general_quadric(const std::array<double, 10>& coeffs, const Bounds3& box,
                             const Mat4& world_from_object = {});

}  // namespace sahara
