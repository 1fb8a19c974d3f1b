#pragma once
/// A ray with its valid parametric interval [tmin, tmax] and a shutter time.
#include <limits>

#include "math/vec3.h"

namespace sahara {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Ray {
    Vec3 origin;
    Vec3 dir;  ///< not necessarily unit length; t is measured in units of |dir|
    float tmin = 0.0f;
    float tmax = kInfinity;
    float time = 0.0f;

    Vec3 at(float t) const { return origin + dir * t; }
};

}  // namespace sahara
