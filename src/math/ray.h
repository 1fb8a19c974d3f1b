#pragma once
/// A ray with its valid parametric interval [tmin, tmax] and a shutter time.
#include <limits>

#include "math/vec3.h"

namespace sahara {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// Reads `x` with a 4-byte load that the vectorizer cannot merge with its
/// neighbours. Traversal reads a ray right after its caller wrote it (a struct
/// copy as two 16-byte stores, or field by field); a wider load that spans two
/// of those stores cannot take its data from the store buffer and waits until
/// both reach the cache.
__attribute__((always_inline)) inline float load_scalar(const float& x) {
    float v = x;
    asm("" : "+x"(v));
    return v;
}

struct Ray {
    Vec3 origin;
    Vec3 dir;  ///< not necessarily unit length; t is measured in units of |dir|
    float tmin = 0.0f;
    float tmax = kInfinity;
    float time = 0.0f;

    Vec3 at(float t) const { return origin + dir * t; }
};

}  // namespace sahara
