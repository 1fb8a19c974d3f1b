#include <doctest/doctest.h>

#include <cmath>

#include "math/transform.h"
#include "render/camera.h"

using namespace sahara;

TEST_CASE("camera: the centre pixel looks at look_at, corners match vfov and aspect") {
    CameraDesc d;
    d.position = {1, 2, 3};
    d.look_at = {4, 6, 3};
    d.up = {0, 0, 1};
    d.vfov = 60;
    const int w = 400, h = 200;
    const Camera cam(d, w, h);
    const Vec3 fwd = normalize(d.look_at - d.position);
    const Ray centre = cam.generate_ray(w / 2.0f, h / 2.0f, {0.5f, 0.5f}, 0.0f);
    CHECK(dot(centre.dir, fwd) == doctest::Approx(1.0f).epsilon(1e-6));
    CHECK(centre.origin == d.position);

    // Top edge centre: angle to forward is vfov / 2.
    const Ray top = cam.generate_ray(w / 2.0f, 0.0f, {0.5f, 0.5f}, 0.0f);
    CHECK(std::acos(dot(top.dir, fwd)) * 180.0f / 3.14159265f == doctest::Approx(30.0f).epsilon(1e-4));
    CHECK(top.dir.z > 0);  // row 0 is the top of the image (up = +z)

    // Top-left corner: tan offsets are (aspect * tan(vfov/2), tan(vfov/2)).
    const Ray corner = cam.generate_ray(0.0f, 0.0f, {0.5f, 0.5f}, 0.0f);
    const Vec3 v = corner.dir / dot(corner.dir, fwd);
    const Vec3 right = normalize(cross(fwd, d.up));
    const float t = std::tan(30.0f * 3.14159265f / 180.0f);
    CHECK(dot(v, right) == doctest::Approx(-2.0f * t).epsilon(1e-5));
    CHECK(v.z == doctest::Approx(t).epsilon(1e-5));
}

TEST_CASE("camera: the 20-minutes Euler form follows the scene-format formula") {
    CameraDesc d;
    d.euler_form = true;
    d.position = {0, 5, -8};
    d.euler = {20, 10, 0};
    d.focal_length = 1.5f;
    const int w = 320, h = 240;
    const Camera cam(d, w, h);
    const Mat4 r = Mat4::rotate_euler(Vec3d(d.euler));
    const Vec3 right = r.apply_vector({1, 0, 0}), up = r.apply_vector({0, 1, 0}),
               front = r.apply_vector({0, 0, 1});
    for (auto [i, j] : {std::pair{0, 0}, {120, 160}, {239, 5}, {17, 300}}) {
        const Vec3 expect = normalize(front * d.focal_length + right * (float(j) / float(w) - 0.5f) +
                                      up * (float(h) / float(w)) * (0.5f - float(i) / float(h)));
        const Ray ray = cam.generate_ray(float(j), float(i), {0.5f, 0.5f}, 0.0f);
        CHECK(dot(ray.dir, expect) == doctest::Approx(1.0f).epsilon(1e-6));
    }
}

TEST_CASE("camera: thin lens rays through one pixel meet on the focal plane") {
    CameraDesc d;
    d.position = {0, 0, 0};
    d.look_at = {0, 10, 0};
    d.aperture = 0.5f;
    const Camera cam(d, 100, 100);
    const Ray a = cam.generate_ray(30, 40, {0.1f, 0.9f}, 0);
    const Ray b = cam.generate_ray(30, 40, {0.8f, 0.2f}, 0);
    CHECK_FALSE(a.origin == b.origin);
    // Both reach the plane y = 10 at the same point.
    const Vec3 pa = a.at((10 - a.origin.y) / a.dir.y), pb = b.at((10 - b.origin.y) / b.dir.y);
    CHECK(length(pa - pb) < 1e-4f);
}
