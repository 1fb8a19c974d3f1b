#pragma once
/// Warps from the unit square to directions and disks.
#include <cmath>
#include <numbers>

#include "math/vec3.h"

namespace sahara {

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = std::numbers::inv_pi_v<float>;

/// Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited": branchless and continuous except at one sign flip).
struct Frame {
    Vec3 s, t, n;
    explicit Frame(const Vec3& nn) : n(nn) {
        float sign = std::copysign(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float b = n.x * n.y * a;
        s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3(b, sign + n.y * n.y * a, -n.y);
    }
    /// A frame whose first axis is `ss` (unit, orthogonal to the unit `nn`).
    Frame(const Vec3& nn, const Vec3& ss) : s(ss), t(cross(nn, ss)), n(nn) {}
    Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
    Vec3 to_local(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

/// Concentric mapping of the square to the unit disk (Shirley and Chiu 1997).
inline Vec2 sample_disk_concentric(Vec2 u) {
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0.0f && b == 0.0f) return {0, 0};
    float r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = kPi / 2.0f - (kPi / 4.0f) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

/// Cosine-weighted direction about +z; pdf = cos(theta) / pi.
inline Vec3 sample_cosine_hemisphere(Vec2 u) {
    Vec2 d = sample_disk_concentric(u);
    float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

/// Uniform direction on the unit sphere; pdf = 1 / (4 pi).
inline Vec3 sample_uniform_sphere(Vec2 u) {
    float z = 1.0f - 2.0f * u.x;
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace sahara
