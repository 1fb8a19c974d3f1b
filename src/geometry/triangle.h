#pragma once
/// Triangle primitive: the watertight ray/triangle test of Woop, Benthin and
/// Wald, "Watertight Ray/Triangle Intersection" (JCGT 2013), plus helpers that
/// turn the barycentrics of an accepted hit into normals and UVs.
///
/// Watertight means: a ray through a shared edge or vertex of a closed mesh
/// hits at least one of the triangles that share it. The test shears the
/// triangle into a space where the ray is the +z axis through the origin and
/// evaluates 2-D edge functions there; when an edge function is exactly 0 in
/// float it is recomputed in double, so neighbouring triangles agree on the
/// sign of the shared edge. What an edge function that is 0 even in double means
/// (the ray passes exactly through an edge or a vertex) is the test's tie-break
/// policy: EdgesInclusive (the renderer's) or EdgesPerturbed (crossing counts).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "geometry/shape.h"
#include "math/bounds.h"
#include "math/ray.h"
#include "math/vec3.h"

namespace sahara {

/// Per-ray constants of the watertight test (computed once per ray).
struct TriangleRay {
    float org[3];
    int kx = 0, ky = 1, kz = 2;    ///< axis permutation: kz = dominant direction axis
    float sx = 0, sy = 0, sz = 1;  ///< shear constants

    TriangleRay() = default;
    /// Picks the axes with branches: cheapest when the rays of one call site share
    /// their dominant axis (camera rays, shadow rays towards one light), which the
    /// branch predictor then learns.
    __attribute__((always_inline)) explicit TriangleRay(const Ray& ray) {
        org[0] = load_scalar(ray.origin.x);
        org[1] = load_scalar(ray.origin.y);
        org[2] = load_scalar(ray.origin.z);
        const Vec3 a = abs(Vec3(load_scalar(ray.dir.x), load_scalar(ray.dir.y), load_scalar(ray.dir.z)));
        kz = max_dimension(a);
        kx = kz == 2 ? 0 : kz + 1;
        ky = kx == 2 ? 0 : kx + 1;
        // Swapping kx and ky for a negative dominant component preserves the
        // winding, so the sign of the determinant tells the side that was hit.
        if (ray.dir[kz] < 0.0f) {
            int t = kx;
            kx = ky;
            ky = t;
        }
        shear(ray.dir[kx], ray.dir[ky], 1.0f / ray.dir[kz]);
    }

    /// sz = 1 / d[kz], sx = d[kx] sz, sy = d[ky] sz: products, not the paper's quotients
    /// d[kx] / d[kz], so that a caller holding 1 / d (the box test's inverse direction)
    /// needs no division. Watertightness needs only that every triangle sees the same
    /// shear, whatever its last bits; sz, which scales t, is the exact quotient still.
    __attribute__((always_inline)) void shear(float dx, float dy, float inv_dz) {
        sx = dx * inv_dz;
        sy = dy * inv_dz;
        sz = inv_dz;
    }

    /// The same constants without branches, for rays in scattered directions (bounces),
    /// whose dominant axis is a coin toss for the branch predictor. Coherent rays (shadow
    /// rays towards a light) keep the constructor, whose branches predict well and let the
    /// core speculate past them.
    /// `inv_dir` is 1 / ray.dir per axis (BvhRay::inv_dir), or null: then it divides.
    __attribute__((always_inline)) static TriangleRay scattered(const Ray& ray, const float inv_dir[3]) {
        TriangleRay tr;
        tr.org[0] = load_scalar(ray.origin.x);
        tr.org[1] = load_scalar(ray.origin.y);
        tr.org[2] = load_scalar(ray.origin.z);
        const float d[3] = {load_scalar(ray.dir.x), load_scalar(ray.dir.y), load_scalar(ray.dir.z)};
        const float ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
        // kz = max_dimension(|dir|): 0 when x beats y and z, else 1 when y beats x and z, else 2.
        const int x_y = ax > ay, x_z = ax > az, y_z = ay > az;
        tr.kz = 2 - 2 * (x_y & x_z) - ((x_y ^ 1) & y_z);
        // The next two axes in cyclic order, as 2-bit entries of a constant (kz 0: 1, 2;
        // kz 1: 2, 0; kz 2: 0, 1), swapped for a negative dominant component.
        const int swap = -int(d[tr.kz] < 0.0f);  // all ones or 0: a ternary compiles to a branch
        const int next = 0x09 >> (2 * tr.kz) & 3, after = 0x12 >> (2 * tr.kz) & 3;
        tr.kx = next ^ ((next ^ after) & swap);
        tr.ky = after ^ ((next ^ after) & swap);
        tr.shear(d[tr.kx], d[tr.ky], inv_dir ? inv_dir[tr.kz] : 1.0f / d[tr.kz]);
        return tr;
    }
};

namespace detail {
/// Edge function recomputed in double (only when the float result is exactly 0).
inline float edge_function_double(float ax, float ay, float bx, float by) {
    return float(double(ax) * double(by) - double(ay) * double(bx));
}
}  // namespace detail

/// Forward error bound on the watertight test's scaled distance T = sz ((u a_z + v b_z) + w c_z),
/// after the conservative-t analysis of Pharr, Jakob and Humphreys (Physically Based
/// Rendering, 4th ed., 6.5.3), redone for this test's order of operations. A hit whose
/// T, signed by det, is at most this bound may lie behind the ray's origin (its float
/// t came out positive through rounding): TriangleVerts::intersect then decides its
/// side in double (detail::hit_ahead_double). Every path (scalar,
/// SSE, AVX, packets) calls this one definition with the maxima over the three sheared
/// vertices of |x|, |y| and |z| (the depth before the sz scale) and with |det|, |sz|; V
/// is float or a GCC vector of floats, so all paths round alike (by reference: an AVX vector
/// passed by value to code compiled without AVX would change the calling convention).
///
/// The error terms, with gamma(n) = n eps / (1 - n eps) and eps = 2^-24: a depth is one
/// subtraction (gamma(1) Z); a sheared x or y three more roundings on operands of at
/// most X + Z, as |sx|, |sy| <= 1 (gamma(5) (X + Z)); an edge function two products and
/// a difference of those, 2 (gamma(2) X Y + dy X + dx Y); the sum over three vertices
/// 3 (gamma(3) E Z + de Z + dz E), with E = max |edge function| <= |det| (the three share a
/// sign). Collected: |sz| Z (k_det |det| + k_xy X Y + k_z Z (X + Y)). The constants are
/// rounded up by a margin that covers the bound's own rounding and second-order terms.
template <class V>
[[gnu::always_inline]] inline void t_scaled_error_bound(const V& max_x, const V& max_y, const V& max_z,
                                                        const V& abs_det, const V& abs_sz, V& bound) {
    constexpr double kEps = 0x1p-24;
    constexpr auto gamma = [](int n) { return n * kEps / (1.0 - n * kEps); };
    constexpr double kMargin = 1.0 + 64.0 * kEps;
    constexpr auto k_det = float(3.0 * (gamma(3) + gamma(1)) * kMargin);
    constexpr auto k_xy = float((6.0 * gamma(2) + 12.0 * gamma(5)) * kMargin);
    constexpr auto k_z = float(6.0 * gamma(5) * kMargin);
    bound = abs_sz * (max_z * ((k_det * abs_det + k_xy * (max_x * max_y)) + k_z * (max_z * (max_x + max_y))));
}

/// Tie-break policies of the watertight test: what an edge function that is 0 even in
/// double means (a ray exactly through an edge or a vertex). With kDecidesZeros the
/// policy's inside(u, v, w, sheared vertices) decides such a hit; without, the sign
/// test counts 0 as either sign.

/// A ray through an edge or a vertex hits every triangle that shares it: a nearest
/// hit then never slips between neighbours (the renderer's test).
struct EdgesInclusive {
    static constexpr bool kDecidesZeros = false;
};

/// A ray through an edge or a vertex hits exactly one of the triangles that share it,
/// for counting crossings. An edge function that is exactly 0 takes the sign it would
/// have with the ray moved by (eps, eps^2) in the sheared plane (simulation of
/// simplicity, Edelsbrunner and Muecke 1990): the sign of its derivative along x, or
/// along y when that is 0. The two triangles of a shared edge see the edge reversed,
/// so exactly one keeps the point; at a vertex exactly one triangle of the fan does.
/// A ray that only touches the surface (a silhouette edge or vertex) gets 0 or 2
/// crossings there, so parity stays exact on closed meshes. Shared vertices must have
/// bit-identical coordinates (welded or not), which any exported mesh has.
struct EdgesPerturbed {
    static constexpr bool kDecidesZeros = true;
    /// Sign of an edge function f, or, when f is 0, of f at the perturbed ray: of gx,
    /// else of gy. 0 only for an edge whose ends project to one point.
    static int perturbed_sign(float f, float gx, float gy) {
        if (f != 0.0f) return f > 0.0f ? 1 : -1;
        if (gx != 0.0f) return gx > 0.0f ? 1 : -1;
        if (gy != 0.0f) return gy > 0.0f ? 1 : -1;
        return 0;
    }
    static bool inside(float u, float v, float w, float ax, float ay, float bx, float by, float cx,
                       float cy) {
        // The edge function p1 x p2 of a ray at (px, py) is (p1 - p) x (p2 - p): its
        // derivatives are (y1 - y2, x2 - x1). A float difference has an exact sign.
        const int su = perturbed_sign(u, cy - by, bx - cx);
        const int sv = perturbed_sign(v, ay - cy, cx - ax);
        const int sw = perturbed_sign(w, by - ay, ax - bx);
        return (su > 0 && sv > 0 && sw > 0) || (su < 0 && sv < 0 && sw < 0);
    }
};

/// The triangle shape: its three vertices as plain arrays (indexable by a runtime axis).
struct TriangleVerts {
    static constexpr bool kBounded = true;

    float p[3][3];

    static TriangleVerts of(const Vec3& a, const Vec3& b, const Vec3& c) {
        return {{{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}}};
    }
    Vec3 vertex(int i) const { return Vec3(p[i][0], p[i][1], p[i][2]); }
    Bounds3 bounds() const {
        Bounds3 b;
        for (int i = 0; i < 3; ++i) b.extend(vertex(i));
        return b;
    }
    /// Nearest hit in (ray.tmin, ray.tmax); u, v are the barycentrics of vertices 1 and 2.
    std::optional<ShapeHit> intersect(const Ray& ray) const {
        return intersect(TriangleRay(ray), ray.tmin, ray.tmax);
    }
    bool occluded(const Ray& ray) const { return intersect(ray).has_value(); }
    /// intersect() with the ray's constants computed once per ray (`tr`), as the
    /// BVH leaves call it, over (tmin, tmax); edges and vertices as TieBreak decides.
    template <class TieBreak = EdgesInclusive>
    std::optional<ShapeHit> intersect(const TriangleRay& tr, float tmin, float tmax) const;
};
static_assert(sizeof(TriangleVerts) == 36);
static_assert(Shape<TriangleVerts>);

namespace detail {
/// Whether the ray meets the plane of `tri` at t > 0: the test's shear and distance in
/// double from the same float inputs (differences and products of floats are then exact
/// or within 2^-53), for hits whose float t lies within its rounding bound of 0.
[[gnu::noinline]] inline bool hit_ahead_double(const TriangleVerts& tri, const TriangleRay& tr) {
    double x[3], y[3], z[3];
    for (int i = 0; i < 3; ++i) {
        z[i] = double(tri.p[i][tr.kz]) - double(tr.org[tr.kz]);
        x[i] = double(tri.p[i][tr.kx]) - double(tr.org[tr.kx]) - double(tr.sx) * z[i];
        y[i] = double(tri.p[i][tr.ky]) - double(tr.org[tr.ky]) - double(tr.sy) * z[i];
    }
    const double u = x[2] * y[1] - y[2] * x[1], v = x[0] * y[2] - y[0] * x[2], w = x[1] * y[0] - y[1] * x[0];
    const double det = u + v + w, t_scaled = u * z[0] + v * z[1] + w * z[2];
    if (det == 0.0 || t_scaled == 0.0) return false;
    // t = sz t_scaled / det: positive when an even number of the three are negative.
    return (t_scaled > 0.0) == ((det > 0.0) == (tr.sz > 0.0f));
}
}  // namespace detail

/// Watertight test of one triangle; a hit needs tmin < t < tmax. Degenerate
/// (zero-area) triangles never hit.
template <class TieBreak>
inline std::optional<ShapeHit> TriangleVerts::intersect(const TriangleRay& tr, float tmin, float tmax) const {
    const TriangleVerts& tri = *this;
    const int kx = tr.kx, ky = tr.ky, kz = tr.kz;
    // Vertices relative to the ray origin.
    const float a_x = tri.p[0][kx] - tr.org[kx], a_y = tri.p[0][ky] - tr.org[ky],
                a_z = tri.p[0][kz] - tr.org[kz];
    const float b_x = tri.p[1][kx] - tr.org[kx], b_y = tri.p[1][ky] - tr.org[ky],
                b_z = tri.p[1][kz] - tr.org[kz];
    const float c_x = tri.p[2][kx] - tr.org[kx], c_y = tri.p[2][ky] - tr.org[ky],
                c_z = tri.p[2][kz] - tr.org[kz];
    // Shear so the ray becomes the +z axis.
    const float ax = a_x - tr.sx * a_z, ay = a_y - tr.sy * a_z;
    const float bx = b_x - tr.sx * b_z, by = b_y - tr.sy * b_z;
    const float cx = c_x - tr.sx * c_z, cy = c_y - tr.sy * c_z;
    // Scaled barycentrics (2-D edge functions).
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = detail::edge_function_double(cx, cy, bx, by);
        v = detail::edge_function_double(ax, ay, cx, cy);
        w = detail::edge_function_double(bx, by, ax, ay);
        if constexpr (TieBreak::kDecidesZeros)
            if (!TieBreak::inside(u, v, w, ax, ay, bx, by, cx, cy)) return std::nullopt;
    }
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return std::nullopt;
    const float det = u + v + w;
    if (det == 0.0f) return std::nullopt;
    // Scaled hit distance, compared against the interval without a division. The z
    // scale multiplies the sum once, not each vertex's z (two products fewer per SIMD
    // step, which follows this order): one rounding per term and one for the scale, as
    // before, so the same error bound. It touches t only; the edge functions, and with
    // them watertightness, never see it.
    const float t_scaled = tr.sz * ((u * a_z + v * b_z) + w * c_z);
    const float abs_det = std::fabs(det);
    const float t_signed = det < 0.0f ? -t_scaled : t_scaled;
    if (!(t_signed > tmin * abs_det) || !(t_signed < tmax * abs_det)) return std::nullopt;
    const float inv_det = 1.0f / det;
    const float t = t_scaled * inv_det;
    // Rounding of the division can push t onto the interval's boundary.
    if (!(t > tmin && t < tmax)) return std::nullopt;
    // A triangle wholly ahead of the origin along the dominant axis is hit at t > 0. On
    // one that is not, a t within its rounding bound of 0 may belong to a plane behind
    // the origin: double decides (the SIMD steps leave exactly these lanes to this test).
    const bool ahead =
        tr.sz < 0.0f ? std::max(std::max(a_z, b_z), c_z) < 0.0f : std::min(std::min(a_z, b_z), c_z) > 0.0f;
    if (!ahead) {
        const auto max_abs = [](float p, float q, float r) {
            return std::max(std::max(std::fabs(p), std::fabs(q)), std::fabs(r));
        };
        float bound;
        t_scaled_error_bound(max_abs(ax, bx, cx), max_abs(ay, by, cy), max_abs(a_z, b_z, c_z), abs_det,
                             std::fabs(tr.sz), bound);
        if (!(t_signed > bound) && !detail::hit_ahead_double(tri, tr)) return std::nullopt;
    }
    return ShapeHit{t, v * inv_det, w * inv_det};
}

/// Unnormalised geometric normal of the triangle (p0, p1, p2): counter-clockwise is the front.
inline Vec3 triangle_geometric_normal(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    return cross(p1 - p0, p2 - p0);
}

/// Unit geometric normal of triangle `i` of any indexed mesh with `positions`
/// and `indices` (TriangleMesh, TriangleSoup); zero for a degenerate triangle.
template <class Mesh>
Vec3 triangle_geometric_normal(const Mesh& mesh, size_t i) {
    const Vec3 n = triangle_geometric_normal(mesh.positions[mesh.indices[3 * i]],
                                             mesh.positions[mesh.indices[3 * i + 1]],
                                             mesh.positions[mesh.indices[3 * i + 2]]);
    const float len = length(n);
    return len > 0.0f ? n / len : Vec3(0.0f);
}

/// Barycentric interpolation of a per-vertex attribute: (1-u-v) a0 + u a1 + v a2.
template <class T>
T barycentric_interpolate(const T& a0, const T& a1, const T& a2, float u, float v) {
    const float w = 1.0f - u - v;
    return a0 * w + a1 * u + a2 * v;
}

/// Interpolated unit shading normal of triangle `i` at barycentrics (u, v);
/// falls back to the geometric normal when the mesh has no normals or they cancel.
template <class Mesh>
Vec3 triangle_shading_normal(const Mesh& mesh, size_t i, float u, float v) {
    if (mesh.normals.empty()) return triangle_geometric_normal(mesh, i);
    const uint32_t* id = &mesh.indices[3 * i];
    const Vec3 n =
        barycentric_interpolate(mesh.normals[id[0]], mesh.normals[id[1]], mesh.normals[id[2]], u, v);
    const float len = length(n);
    return len > 0.0f ? n / len : triangle_geometric_normal(mesh, i);
}

/// Interpolated UV of triangle `i` at barycentrics (u, v); (u, v) itself when the mesh has no UVs.
template <class Mesh>
Vec2 triangle_uv(const Mesh& mesh, size_t i, float u, float v) {
    if (mesh.uvs.empty()) return Vec2{u, v};
    const uint32_t* id = &mesh.indices[3 * i];
    const Vec2 &a = mesh.uvs[id[0]], &b = mesh.uvs[id[1]], &c = mesh.uvs[id[2]];
    const float w = 1.0f - u - v;
    return Vec2{a.x * w + b.x * u + c.x * v, a.y * w + b.y * u + c.y * v};
}

}  // namespace sahara
