#pragma once
/// Small 3-vector used for points, directions and linear RGB colours.
/// `Vec3` (float) is the geometry/shading type; `Vec3d` (double) is used where
/// float cannot carry the precision (sphere roots far from the origin).
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sahara {

template <class T>
struct TVec3 {
    T x = 0, y = 0, z = 0;

    constexpr TVec3() = default;
    constexpr TVec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit TVec3(T s) : x(s), y(s), z(s) {}
    template <class U>
    constexpr explicit TVec3(const TVec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr TVec3 operator-() const { return {-x, -y, -z}; }
    constexpr TVec3& operator+=(const TVec3& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    constexpr TVec3& operator-=(const TVec3& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    constexpr TVec3& operator*=(const TVec3& o) {
        x *= o.x;
        y *= o.y;
        z *= o.z;
        return *this;
    }
    constexpr TVec3& operator*=(T s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    constexpr TVec3& operator/=(T s) { return *this *= T(1) / s; }
    constexpr bool operator==(const TVec3&) const = default;
};

using Vec3 = TVec3<float>;
using Vec3d = TVec3<double>;
/// Linear Rec.709 RGB radiance or reflectance.
using Rgb = TVec3<float>;

template <class T>
constexpr TVec3<T> operator+(TVec3<T> a, const TVec3<T>& b) {
    return a += b;
}
template <class T>
constexpr TVec3<T> operator-(TVec3<T> a, const TVec3<T>& b) {
    return a -= b;
}
template <class T>
constexpr TVec3<T> operator*(TVec3<T> a, const TVec3<T>& b) {
    return a *= b;
}
template <class T>
constexpr TVec3<T> operator*(TVec3<T> a, T s) {
    return a *= s;
}
template <class T>
constexpr TVec3<T> operator*(T s, TVec3<T> a) {
    return a *= s;
}
template <class T>
constexpr TVec3<T> operator/(TVec3<T> a, T s) {
    return a /= s;
}
template <class T>
constexpr TVec3<T> operator/(TVec3<T> a, const TVec3<T>& b) {
    return {a.x / b.x, a.y / b.y, a.z / b.z};
}

template <class T>
constexpr T dot(const TVec3<T>& a, const TVec3<T>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
constexpr TVec3<T> cross(const TVec3<T>& a, const TVec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
constexpr T length_squared(const TVec3<T>& a) {
    return dot(a, a);
}
template <class T>
inline T length(const TVec3<T>& a) {
    return std::sqrt(dot(a, a));
}
template <class T>
inline TVec3<T> normalize(const TVec3<T>& a) {
    return a / length(a);
}
template <class T>
constexpr TVec3<T> min(const TVec3<T>& a, const TVec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <class T>
constexpr TVec3<T> max(const TVec3<T>& a, const TVec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <class T>
inline TVec3<T> abs(const TVec3<T>& a) {
    return {std::abs(a.x), std::abs(a.y), std::abs(a.z)};
}
template <class T>
constexpr T max_component(const TVec3<T>& a) {
    return std::max(a.x, std::max(a.y, a.z));
}
template <class T>
constexpr T min_component(const TVec3<T>& a) {
    return std::min(a.x, std::min(a.y, a.z));
}
/// Index (0, 1, 2) of the largest component.
template <class T>
constexpr int max_dimension(const TVec3<T>& a) {
    return (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
}
template <class T>
inline bool is_finite(const TVec3<T>& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
template <class T>
constexpr TVec3<T> lerp(T t, const TVec3<T>& a, const TVec3<T>& b) {
    return (T(1) - t) * a + t * b;
}
/// Mean of the three channels (used for Russian roulette and error metrics).
constexpr float average(const Rgb& c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }
/// Rec.709 luminance of a linear RGB colour.
constexpr float luminance(const Rgb& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

struct Vec2 {
    float x = 0, y = 0;
};

}  // namespace sahara
