#pragma once
/// Axis-aligned bounding box. An empty box has lo = +inf, hi = -inf so that
/// extending it with anything yields that thing.
#include "math/ray.h"
#include "math/vec3.h"

namespace sahara {

struct Bounds3 {
    Vec3 lo{kInfinity};
    Vec3 hi{-kInfinity};

    static Bounds3 of_point(const Vec3& p) { return {p, p}; }
    void extend(const Vec3& p) {
        lo = min(lo, p);
        hi = max(hi, p);
    }
    void extend(const Bounds3& b) {
        lo = min(lo, b.lo);
        hi = max(hi, b.hi);
    }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    Vec3 extent() const { return hi - lo; }
    Vec3 center() const { return (lo + hi) * 0.5f; }
    /// Surface area; 0 for an empty box.
    float surface_area() const {
        if (empty()) return 0.0f;
        Vec3 e = extent();
        return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    bool contains(const Bounds3& b) const {
        return b.lo.x >= lo.x && b.lo.y >= lo.y && b.lo.z >= lo.z && b.hi.x <= hi.x && b.hi.y <= hi.y &&
               b.hi.z <= hi.z;
    }
    bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
    }
};

inline Bounds3 join(Bounds3 a, const Bounds3& b) {
    a.extend(b);
    return a;
}

}  // namespace sahara
