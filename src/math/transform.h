#pragma once
/// Affine transforms as row-major 4x4 matrices, applied at load time.
#include <array>
#include <cmath>
#include <numbers>

#include "math/vec3.h"

namespace sahara {

struct Mat4 {
    /// m[row][col]; points are column vectors: p' = M p.
    std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};

    static Mat4 identity() { return {}; }
    static Mat4 translate(const Vec3d& t) {
        Mat4 r;
        r.m[0][3] = t.x;
        r.m[1][3] = t.y;
        r.m[2][3] = t.z;
        return r;
    }
    static Mat4 scale(const Vec3d& s) {
        Mat4 r;
        r.m[0][0] = s.x;
        r.m[1][1] = s.y;
        r.m[2][2] = s.z;
        return r;
    }
    /// Rotation by `deg` degrees about coordinate axis `axis` (0 = X, 1 = Y, 2 = Z), right-handed.
    static Mat4 rotate_axis(int axis, double deg) {
        double a = deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
        Mat4 r;
        int i = (axis + 1) % 3, j = (axis + 2) % 3;
        r.m[i][i] = c;
        r.m[i][j] = -s;
        r.m[j][i] = s;
        r.m[j][j] = c;
        return r;
    }
    /// Euler rotation in degrees: about X first, then Y, then Z (R = Rz Ry Rx).
    static Mat4 rotate_euler(const Vec3d& deg) {
        return rotate_axis(2, deg.z) * rotate_axis(1, deg.y) * rotate_axis(0, deg.x);
    }
    /// Rotation from a unit quaternion (x, y, z, w), as glTF stores it.
    static Mat4 rotate_quaternion(double x, double y, double z, double w) {
        Mat4 r;
        r.m[0][0] = 1 - 2 * (y * y + z * z);
        r.m[0][1] = 2 * (x * y - z * w);
        r.m[0][2] = 2 * (x * z + y * w);
        r.m[1][0] = 2 * (x * y + z * w);
        r.m[1][1] = 1 - 2 * (x * x + z * z);
        r.m[1][2] = 2 * (y * z - x * w);
        r.m[2][0] = 2 * (x * z - y * w);
        r.m[2][1] = 2 * (y * z + x * w);
        r.m[2][2] = 1 - 2 * (x * x + y * y);
        return r;
    }

    friend Mat4 operator*(const Mat4& a, const Mat4& b) {
        Mat4 r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
                r.m[i][j] = s;
            }
        return r;
    }

    /// The point in double precision: far-away inputs (1e7 plus a small
    /// offset) keep their digits until the caller rounds the result.
    Vec3d map_point(const Vec3d& p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    Vec3 apply_point(const Vec3& pf) const { return Vec3(map_point(Vec3d(pf))); }
    Vec3 apply_vector(const Vec3& vf) const {
        const Vec3d v(vf);
        return Vec3(float(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z),
                    float(m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z),
                    float(m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z));
    }
    /// Determinant of the upper 3x3 (negative: the transform mirrors, flip winding).
    double determinant3() const {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
    /// Normals transform by the inverse transpose of the upper 3x3; the
    /// cofactor matrix equals it up to the (positive or negative) determinant.
    Vec3 apply_normal(const Vec3& nf) const {
        const Vec3d n(nf);
        double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
               c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
        double c10 = m[0][2] * m[2][1] - m[0][1] * m[2][2], c11 = m[0][0] * m[2][2] - m[0][2] * m[2][0],
               c12 = m[0][1] * m[2][0] - m[0][0] * m[2][1];
        double c20 = m[0][1] * m[1][2] - m[0][2] * m[1][1], c21 = m[0][2] * m[1][0] - m[0][0] * m[1][2],
               c22 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        double s = determinant3() < 0 ? -1.0 : 1.0;
        Vec3d r(s * (c00 * n.x + c01 * n.y + c02 * n.z), s * (c10 * n.x + c11 * n.y + c12 * n.z),
                s * (c20 * n.x + c21 * n.y + c22 * n.z));
        double len = length(r);
        return len > 0 ? Vec3(r / len) : Vec3(0, 0, 0);
    }
};

/// Inverse of an affine matrix (last row 0 0 0 1, invertible upper 3x3).
inline Mat4 affine_inverse(const Mat4& m) {
    // Inverse 3x3 = adjugate / determinant; translation = -inverse3x3 * t.
    const auto& a = m.m;
    double det = m.determinant3();
    Mat4 r;
    r.m[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
    r.m[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
    r.m[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
    r.m[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
    r.m[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
    r.m[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
    r.m[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
    r.m[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
    r.m[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
    for (int i = 0; i < 3; ++i)
        r.m[i][3] = -(r.m[i][0] * a[0][3] + r.m[i][1] * a[1][3] + r.m[i][2] * a[2][3]);
    return r;
}

}  // namespace sahara
