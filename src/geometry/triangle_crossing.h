#pragma once
/// The watertight ray/triangle test (geometry/triangle.h) with a consistent
/// tie-break for rays through edges and vertices, for counting crossings.
///
/// intersect_triangle accepts a hit whose edge function is exactly 0, so a ray
/// through a shared edge hits both triangles and a ray through a vertex hits its
/// whole fan: right for a nearest hit, wrong for a count. Here an edge function
/// that is exactly 0 takes the sign it would have if the ray were moved by
/// (eps, eps^2) in the sheared plane (simulation of simplicity, Edelsbrunner and
/// Muecke 1990): the sign of its derivative along x, or along y when that is 0.
/// The two triangles of a shared edge see the edge reversed, so exactly one of
/// them keeps the point; at a vertex exactly one triangle of the fan does. A ray
/// that only touches the surface (a silhouette edge or vertex) gets 0 or 2
/// crossings there, so parity stays exact on closed meshes. Shared vertices must
/// have bit-identical coordinates (welded or not), which any exported mesh has.
#include "geometry/shape.h"
#include "geometry/triangle.h"

namespace sahara {

namespace detail {
/// Sign of an edge function f (exact: the float and double forms agree on it), or,
/// when f is 0, the sign of f at the perturbed ray: of gx, else of gy. 0 only for an
/// edge whose two ends project to the same point (no perturbation separates them).
inline int perturbed_sign(float f, float gx, float gy) {
    if (f != 0.0f) return f > 0.0f ? 1 : -1;
    if (gx != 0.0f) return gx > 0.0f ? 1 : -1;
    if (gy != 0.0f) return gy > 0.0f ? 1 : -1;
    return 0;
}
}  // namespace detail

/// Whether the ray crosses the triangle with tmin < t < tmax, edges and vertices
/// resolved as above. `out` gets the same t, u, v intersect_triangle computes.
inline bool cross_triangle(const TriangleRay& tr, const TriangleVerts& tri, float tmin, float tmax,
                           ShapeHit& out) {
    const int kx = tr.kx, ky = tr.ky, kz = tr.kz;
    const float a_x = tri.p[0][kx] - tr.org[kx], a_y = tri.p[0][ky] - tr.org[ky],
                a_z = tri.p[0][kz] - tr.org[kz];
    const float b_x = tri.p[1][kx] - tr.org[kx], b_y = tri.p[1][ky] - tr.org[ky],
                b_z = tri.p[1][kz] - tr.org[kz];
    const float c_x = tri.p[2][kx] - tr.org[kx], c_y = tri.p[2][ky] - tr.org[ky],
                c_z = tri.p[2][kz] - tr.org[kz];
    const float ax = a_x - tr.sx * a_z, ay = a_y - tr.sy * a_z;
    const float bx = b_x - tr.sx * b_z, by = b_y - tr.sy * b_z;
    const float cx = c_x - tr.sx * c_z, cy = c_y - tr.sy * c_z;
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = detail::edge_function_double(cx, cy, bx, by);
        v = detail::edge_function_double(ax, ay, cx, cy);
        w = detail::edge_function_double(bx, by, ax, ay);
        // An edge function p1 x p2 of the ray at (px, py) is (p1 - p) x (p2 - p):
        // its derivatives are (y1 - y2, x2 - x1).
        const int su = detail::perturbed_sign(u, cy - by, bx - cx);
        const int sv = detail::perturbed_sign(v, ay - cy, cx - ax);
        const int sw = detail::perturbed_sign(w, by - ay, ax - bx);
        if (!((su > 0 && sv > 0 && sw > 0) || (su < 0 && sv < 0 && sw < 0))) return false;
    } else if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) {
        return false;
    }
    const float det = u + v + w;
    if (det == 0.0f) return false;
    const float t_scaled = u * (tr.sz * a_z) + v * (tr.sz * b_z) + w * (tr.sz * c_z);
    const float abs_det = std::fabs(det);
    const float t_signed = det < 0.0f ? -t_scaled : t_scaled;
    if (!(t_signed > tmin * abs_det) || !(t_signed < tmax * abs_det)) return false;
    const float inv_det = 1.0f / det;
    out = {t_scaled * inv_det, v * inv_det, w * inv_det};
    return out.t > tmin && out.t < tmax;
}

}  // namespace sahara
