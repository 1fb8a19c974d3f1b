#include "geometry/quadric.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "base/error.h"

namespace sahara {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Relative slack on the cap radius so that a ray through the rim of a capped
/// cylinder or cone hits the side or the cap, never slips between the two.
constexpr double kCapSlack = 1e-9;

/// Inverse of an affine transform (upper 3x3 by cofactors, translation undone).
Mat4 invert_affine(const Mat4& m) {
    const auto& a = m.m;
    const double det = m.determinant3();
    const double inv = 1.0 / det;
    Mat4 r;
    r.m[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) * inv;
    r.m[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) * inv;
    r.m[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) * inv;
    r.m[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) * inv;
    r.m[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) * inv;
    r.m[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) * inv;
    r.m[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) * inv;
    r.m[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) * inv;
    r.m[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) * inv;
    for (int i = 0; i < 3; ++i)
        r.m[i][3] = -(r.m[i][0] * a[0][3] + r.m[i][1] * a[1][3] + r.m[i][2] * a[2][3]);
    return r;
}

Vec3d point_to(const Mat4& m, const Vec3d& p) {
    return {m.m[0][0] * p.x + m.m[0][1] * p.y + m.m[0][2] * p.z + m.m[0][3],
            m.m[1][0] * p.x + m.m[1][1] * p.y + m.m[1][2] * p.z + m.m[1][3],
            m.m[2][0] * p.x + m.m[2][1] * p.y + m.m[2][2] * p.z + m.m[2][3]};
}
Vec3d vector_to(const Mat4& m, const Vec3d& v) {
    return {m.m[0][0] * v.x + m.m[0][1] * v.y + m.m[0][2] * v.z,
            m.m[1][0] * v.x + m.m[1][1] * v.y + m.m[1][2] * v.z,
            m.m[2][0] * v.x + m.m[2][1] * v.y + m.m[2][2] * v.z};
}

/// Real roots of a t² + b t + c = 0 in ascending order; returns how many (0..2).
/// Uses q = -(b + sign(b) sqrt(b² - 4ac)) / 2, roots q/a and c/q, which avoids
/// the cancellation of the textbook formula and degrades gracefully to the
/// linear root -c/b as a -> 0 (q/a then runs off to infinity and is dropped).
int solve_quadratic(double a, double b, double c, double roots[2]) {
    if (a == 0.0) {
        if (b == 0.0) return 0;
        roots[0] = -c / b;
        return 1;
    }
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0 || !std::isfinite(disc)) return 0;
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    if (q == 0.0) {  // b = 0 and a c = 0: a double root at 0
        roots[0] = 0.0;
        return 1;
    }
    // For tiny a, q / a may be huge or infinite; the callers reject it.
    roots[0] = std::min(q / a, c / q);
    roots[1] = std::max(q / a, c / q);
    return 2;
}

bool inside_clip(const Quadric& q, const Vec3d& p) {
    return p.x >= q.clip_lo.x && p.x <= q.clip_hi.x && p.y >= q.clip_lo.y && p.y <= q.clip_hi.y &&
           p.z >= q.clip_lo.z && p.z <= q.clip_hi.z;
}

/// Accepts an object-frame parameter (unit direction) if it maps to a float t
/// strictly inside the ray's interval; returns the float t or -1.
float accept_t(double t_unit, double inv_len, const Ray& ray) {
    const double t = t_unit * inv_len;
    if (!(t > double(ray.tmin) && t < double(ray.tmax))) return -1.0f;
    if (t > double(std::numeric_limits<float>::max())) return -1.0f;
    const float tf = float(t);
    return (tf > ray.tmin && tf < ray.tmax) ? tf : -1.0f;
}

/// Reference point the ray origin is moved to before solving: the middle of
/// the clipped region, or the object origin when that is unbounded.
Vec3d reference_point(const Quadric& q) {
    Vec3d c(0.0);
    for (int k = 0; k < 3; ++k)
        if (std::isfinite(q.clip_lo[k]) && std::isfinite(q.clip_hi[k]))
            c[k] = 0.5 * (q.clip_lo[k] + q.clip_hi[k]);
    return c;
}

}  // namespace

double Quadric::eval(const Vec3d& p) const {
    const auto& k = coeffs;
    return p.x * (k[0] * p.x + k[3] * p.y + k[4] * p.z + k[6]) + p.y * (k[1] * p.y + k[5] * p.z + k[7]) +
           p.z * (k[2] * p.z + k[8]) + k[9];
}

Vec3d Quadric::gradient(const Vec3d& p) const {
    const auto& k = coeffs;
    return {2.0 * k[0] * p.x + k[3] * p.y + k[4] * p.z + k[6],
            2.0 * k[1] * p.y + k[3] * p.x + k[5] * p.z + k[7],
            2.0 * k[2] * p.z + k[4] * p.x + k[5] * p.y + k[8]};
}

std::optional<ShapeHit> Quadric::intersect(const Ray& ray) const {
    Vec3d o = point_to(object_from_world, Vec3d(ray.origin));
    Vec3d d = vector_to(object_from_world, Vec3d(ray.dir));
    const double len = length(d);
    if (!(len > 0.0) || !std::isfinite(len)) return std::nullopt;
    const double inv_len = 1.0 / len;
    d = d * inv_len;  // unit: parameters below are object-frame distances
    // Move the origin to the ray point nearest the object so that the
    // coefficients stay small and b² - 4ac does not cancel for distant rays.
    const double shift = dot(solve_origin - o, d);
    o = o + d * shift;
    const auto& k = coeffs;
    const double a =
        d.x * (k[0] * d.x + k[3] * d.y + k[4] * d.z) + d.y * (k[1] * d.y + k[5] * d.z) + k[2] * d.z * d.z;
    const double b = dot(gradient(o), d);
    const double c = eval(o);
    double roots[2];
    const int n = solve_quadratic(a, b, c, roots);
    std::optional<ShapeHit> best;
    for (int i = 0; i < n; ++i) {  // ascending: the first accepted root is the nearest
        if (!inside_clip(*this, o + d * roots[i])) continue;
        const float t = accept_t(shift + roots[i], inv_len, ray);
        if (t >= 0.0f) {
            best = ShapeHit{t, 0.0f, 0.0f, uint32_t(QuadricPart::side)};
            break;
        }
    }
    if ((cap_bottom || cap_top) && d.z != 0.0) {
        for (int side = 0; side < 2; ++side) {
            if (!(side == 0 ? cap_bottom : cap_top)) continue;
            const double zc = side == 0 ? clip_lo.z : clip_hi.z;
            const double tc = (zc - o.z) / d.z;
            const double x = o.x + d.x * tc, y = o.y + d.y * tc;
            if (x * x + y * y > 1.0 + kCapSlack) continue;
            const float t = accept_t(shift + tc, inv_len, ray);
            if (t >= 0.0f && (!best || t < best->t))
                best = ShapeHit{t, 0.0f, 0.0f,
                                uint32_t(side == 0 ? QuadricPart::bottom_cap : QuadricPart::top_cap)};
        }
    }
    return best;
}

/// The BVH keeps only t and the primitive id (geometry/hit.h's 16-byte Hit, one store
/// per closer hit on the triangle path), so the part of the accepted hit is found again
/// here, once per shaded quadric hit: in the open interval between the floats next to t,
/// the only candidates intersect() accepts are those that rounded to t itself, and it
/// breaks ties among them in the same order as it did over the whole interval.
ShapeHit Quadric::hit_at(const Ray& ray, float t) const {
    Ray around = ray;
    around.tmin = std::nextafter(t, -kInfinity);
    around.tmax = std::nextafter(t, kInfinity);
    const std::optional<ShapeHit> h = intersect(around);
    return ShapeHit{t, 0.0f, 0.0f, h ? h->part : uint32_t(QuadricPart::side)};
}

QuadricSurface Quadric::surface(const Ray& ray, const ShapeHit& hit) const {
    const Vec3d o = point_to(object_from_world, Vec3d(ray.origin));
    const Vec3d d = vector_to(object_from_world, Vec3d(ray.dir));
    Vec3d p = o + d * double(hit.t);
    Vec3d g;
    QuadricSurface s;
    if (hit.part == uint32_t(QuadricPart::side)) {
        // One Newton step along the gradient projects p back onto f = 0,
        // removing most of the error of origin + t * dir (t is a float).
        g = gradient(p);
        const double gg = dot(g, g);
        if (gg > 0.0) p = p - g * (eval(p) / gg);
        g = gradient(p);
        if (!(dot(g, g) > 0.0)) g = -d;  // singular point (cone apex): face the ray
        if (form == QuadricForm::ellipsoid) {
            const Vec3d u = p / length(p);
            s.uv = {float(0.5 + std::atan2(u.y, u.x) * (0.5 * std::numbers::inv_pi)),
                    float(0.5 + std::asin(std::clamp(u.z, -1.0, 1.0)) * std::numbers::inv_pi)};
        } else if (form != QuadricForm::general) {
            const double z0 = clip_lo.z == -kInf ? 0.0 : clip_lo.z;  // paraboloid: vertex at z = 0
            s.uv = {float(0.5 + std::atan2(p.y, p.x) * (0.5 * std::numbers::inv_pi)),
                    float((p.z - z0) / (clip_hi.z - z0))};
        } else {
            s.uv = {0.0f, 0.0f};
        }
    } else {
        const bool top = hit.part == uint32_t(QuadricPart::top_cap);
        p.z = top ? clip_hi.z : clip_lo.z;
        g = Vec3d(0.0, 0.0, top ? 1.0 : -1.0);
        s.uv = {float(0.5 + 0.5 * p.x), float(0.5 + 0.5 * p.y)};
    }
    s.p = Vec3(point_to(world_from_object, p));
    s.n = world_from_object.apply_normal(Vec3(g / length(g)));
    s.front_face = dot(s.n, ray.dir) < 0.0f;
    return s;
}

Vec3 Quadric::normal(const Vec3& p_world) const {
    const Vec3d p = point_to(object_from_world, Vec3d(p_world));
    const double r2 = p.x * p.x + p.y * p.y;
    Vec3d g = gradient(p);
    const double eps = 1e-6 * std::max(1.0, std::abs(clip_hi.z));
    if (cap_top && std::abs(p.z - clip_hi.z) < eps && r2 < 1.0 - eps) g = {0, 0, 1};
    if (cap_bottom && std::abs(p.z - clip_lo.z) < eps && r2 < 1.0 - eps) g = {0, 0, -1};
    if (!(dot(g, g) > 0.0)) g = {0, 0, 1};
    return world_from_object.apply_normal(Vec3(g / length(g)));
}

namespace {

/// Object-frame box around the clipped surface (finite for every form).
void object_box(const Quadric& q, Vec3d& lo, Vec3d& hi) {
    switch (q.form) {
        case QuadricForm::ellipsoid:
            lo = Vec3d(-1.0);
            hi = Vec3d(1.0);
            return;
        case QuadricForm::cylinder:
        case QuadricForm::cone:
        case QuadricForm::paraboloid:
            lo = {-1, -1, 0};
            hi = {1, 1, 1};
            return;
        case QuadricForm::hyperboloid: {
            const double r = std::sqrt(1.0 - q.coeffs[2]);  // radius at z = +-1
            lo = {-r, -r, -1};
            hi = {r, r, 1};
            return;
        }
        case QuadricForm::general:
            lo = q.clip_lo;
            hi = q.clip_hi;
            return;
    }
}

/// Grows a box by a relative margin and rounds it outwards to float, so that
/// float slab tests never cut off a point of the exact surface.
Bounds3 padded_bounds(const Vec3d& lo, const Vec3d& hi) {
    const double margin =
        1e-6 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, std::abs(lo.x), std::abs(hi.x),
                         std::abs(lo.y), std::abs(hi.y), std::abs(lo.z), std::abs(hi.z)});
    Bounds3 b;
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::nextafter(float(lo[k] - margin), -kInfinity);
        b.hi[k] = std::nextafter(float(hi[k] + margin), kInfinity);
    }
    return b;
}

}  // namespace

void Quadric::finalize() {
    object_from_world = invert_affine(world_from_object);
    solve_origin = reference_point(*this);
    const auto& m = world_from_object.m;
    if (form == QuadricForm::ellipsoid) {
        // The image of the unit sphere under M extends sqrt(sum_j M_ij²) along world axis i.
        Vec3d c(m[0][3], m[1][3], m[2][3]), e;
        for (int i = 0; i < 3; ++i)
            e[i] = std::sqrt(m[i][0] * m[i][0] + m[i][1] * m[i][1] + m[i][2] * m[i][2]);
        world_bounds = padded_bounds(c - e, c + e);
        return;
    }
    Vec3d lo, hi;
    object_box(*this, lo, hi);
    Vec3d wlo(kInf), whi(-kInf);
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3d p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
        const Vec3d w = point_to(world_from_object, p);
        wlo = min(wlo, w);
        whi = max(whi, w);
    }
    world_bounds = padded_bounds(wlo, whi);
}

namespace {

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

void require_positive(const char* name, double v) {
    if (!(v > 0.0) || !std::isfinite(v))
        throw InputError(std::string(name) + ": expected a number > 0, got " + number_text(v));
}

void require_transform(const Mat4& m) {
    const double det = m.determinant3();
    if (!(std::abs(det) > 0.0) || !std::isfinite(det))
        throw InputError("transform: expected an invertible matrix (a scale of 0 flattens the object)");
}

/// Rotation taking +z to normalize(axis), with a continuous orthonormal basis
/// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
Mat4 rotate_z_to(const Vec3& axis_f) {
    const Vec3d axis(axis_f);
    const double len = length(axis);
    if (!(len > 0.0) || !std::isfinite(len)) throw InputError("axis: expected a non-zero vector");
    const Vec3d n = axis / len;
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
    const Vec3d s(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), t(b, sign + n.y * n.y * a, -n.y);
    Mat4 r;
    for (int i = 0; i < 3; ++i) {
        r.m[i][0] = s[i];
        r.m[i][1] = t[i];
        r.m[i][2] = n[i];
    }
    return r;
}

/// A named surface of revolution about +z: placement = user * T(origin) * R(axis) * S(rxy, rxy, sz).
Quadric make_revolved(QuadricForm form, const std::array<double, 10>& coeffs, const Vec3& origin,
                      const Vec3& axis, double rxy, double sz, const Mat4& world_from_object) {
    require_transform(world_from_object);
    Quadric q;
    q.form = form;
    q.coeffs = coeffs;
    q.world_from_object = world_from_object * Mat4::translate(Vec3d(origin)) * rotate_z_to(axis) *
                          Mat4::scale(Vec3d(rxy, rxy, sz));
    return q;
}

}  // namespace

Quadric make_ellipsoid(const Vec3& center, const Vec3& radii, const Mat4& world_from_object) {
    require_positive("radii[0]", double(radii.x));
    require_positive("radii[1]", double(radii.y));
    require_positive("radii[2]", double(radii.z));
    require_transform(world_from_object);
    Quadric q;
    q.form = QuadricForm::ellipsoid;
    q.coeffs = {1, 1, 1, 0, 0, 0, 0, 0, 0, -1};
    q.world_from_object = world_from_object * Mat4::translate(Vec3d(center)) * Mat4::scale(Vec3d(radii));
    q.finalize();
    return q;
}

Quadric make_cylinder(const Vec3& base, const Vec3& axis, float radius, float height, bool capped,
                      const Mat4& world_from_object) {
    require_positive("radius", double(radius));
    require_positive("height", double(height));
    Quadric q = make_revolved(QuadricForm::cylinder, {1, 1, 0, 0, 0, 0, 0, 0, 0, -1}, base, axis, radius,
                              height, world_from_object);
    q.clip_lo.z = 0.0;
    q.clip_hi.z = 1.0;
    q.cap_bottom = q.cap_top = capped;
    q.finalize();
    return q;
}

Quadric make_cone(const Vec3& apex, const Vec3& axis, float angle_deg, float height, bool capped,
                  const Mat4& world_from_object) {
    if (!(angle_deg > 0.0f && angle_deg < 90.0f))
        throw InputError("angle: expected degrees in (0, 90), got " + number_text(double(angle_deg)));
    require_positive("height", double(height));
    const double r = double(height) * std::tan(double(angle_deg) * std::numbers::pi / 180.0);
    Quadric q = make_revolved(QuadricForm::cone, {1, 1, -1, 0, 0, 0, 0, 0, 0, 0}, apex, axis, r, height,
                              world_from_object);
    q.clip_lo.z = 0.0;
    q.clip_hi.z = 1.0;
    q.cap_top = capped;
    q.finalize();
    return q;
}

Quadric make_paraboloid(const Vec3& vertex, const Vec3& axis, float radius, float height,
                        const Mat4& world_from_object) {
    require_positive("radius", double(radius));
    require_positive("height", double(height));
    Quadric q = make_revolved(QuadricForm::paraboloid, {1, 1, 0, 0, 0, 0, 0, 0, -1, 0}, vertex, axis, radius,
                              height, world_from_object);
    q.clip_hi.z = 1.0;  // x² + y² = z >= 0 already bounds it below
    q.finalize();
    return q;
}

Quadric make_hyperboloid(const Vec3& center, const Vec3& axis, float radius, float waist, float height,
                         const Mat4& world_from_object) {
    require_positive("waist", double(waist));
    require_positive("height", double(height));
    if (!(radius >= waist) || !std::isfinite(radius))
        throw InputError("radius: expected a number >= waist (" + number_text(double(waist)) + "), got " +
                         number_text(double(radius)));
    const double ratio = double(radius) / double(waist);
    Quadric q = make_revolved(QuadricForm::hyperboloid, {1, 1, -(ratio * ratio - 1.0), 0, 0, 0, 0, 0, 0, -1},
                              center, axis, waist, 0.5 * double(height), world_from_object);
    q.clip_lo.z = -1.0;
    q.clip_hi.z = 1.0;
    q.finalize();
    return q;
}

Quadric make_general_quadric(const std::array<double, 10>& coeffs, const Bounds3& box,
                             const Mat4& world_from_object) {
    for (double c : coeffs)
        if (!std::isfinite(c)) throw InputError("coefficients: expected finite numbers");
    bool any_nonzero = false;
    for (int i = 0; i < 9; ++i) any_nonzero |= coeffs[size_t(i)] != 0.0;
    if (!any_nonzero) throw InputError("coefficients: A..I are all zero (no surface)");
    if (box.empty() || !is_finite(box.lo) || !is_finite(box.hi))
        throw InputError("bounds: expected finite min <= max");
    require_transform(world_from_object);
    Quadric q;
    q.form = QuadricForm::general;
    q.coeffs = coeffs;
    q.clip_lo = Vec3d(box.lo);
    q.clip_hi = Vec3d(box.hi);
    q.world_from_object = world_from_object;
    q.finalize();
    return q;
}

}  // namespace sahara
