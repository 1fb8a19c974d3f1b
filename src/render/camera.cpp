#include "render/camera.h"

#include <cmath>

#include "math/sampling.h"
#include "math/transform.h"

namespace sahara {

Camera::Camera(const CameraDesc& d, int width, int height) : width_(width), height_(height) {
    const float aspect = float(width) / float(height);
    origin_ = d.position;
    if (d.euler_form) {
        // Basis right=+X, up=+Y, front=+Z rotated about X, then Y, then Z; the
        // view plane is 1 unit wide at distance focal_length.
        Mat4 r = Mat4::rotate_euler(Vec3d(d.euler));
        right_ = normalize(r.apply_vector({1, 0, 0}));
        up_ = normalize(r.apply_vector({0, 1, 0}));
        forward_ = normalize(r.apply_vector({0, 0, 1}));
        half_w_ = 0.5f / d.focal_length;
        half_h_ = half_w_ / aspect;
        focus_distance_ = d.focus_distance.value_or(d.focal_length);
    } else {
        if (d.has_basis) {
            forward_ = normalize(d.basis_forward);
            right_ = normalize(d.basis_right);
            up_ = normalize(d.basis_up);
        } else {
            forward_ = normalize(d.look_at - d.position);
            right_ = normalize(cross(forward_, d.up));
            up_ = cross(right_, forward_);
        }
        ortho_ = d.orthographic;
        half_h_ = ortho_ ? 0.5f * d.ortho_height : std::tan(0.5f * d.vfov * kPi / 180.0f);
        half_w_ = half_h_ * aspect;
        focus_distance_ = d.focus_distance.value_or(d.has_basis ? 1.0f : length(d.look_at - d.position));
    }
    lens_radius_ = 0.5f * d.aperture;
    shutter_open_ = d.shutter_open;
    shutter_close_ = d.shutter_close;
}

Ray Camera::generate_ray(float px, float py, Vec2 lens, float time_u) const {
    const float sx = (2.0f * px / float(width_) - 1.0f) * half_w_;
    const float sy = (1.0f - 2.0f * py / float(height_)) * half_h_;
    Ray ray;
    if (ortho_) {
        ray.origin = origin_ + right_ * sx + up_ * sy;
        ray.dir = forward_;
    } else {
        ray.origin = origin_;
        ray.dir = forward_ + right_ * sx + up_ * sy;
        if (lens_radius_ > 0) {
            // Thin lens: all rays through one pixel meet on the focal plane.
            Vec3 focus = origin_ + ray.dir * focus_distance_;
            Vec2 d = sample_disk_concentric(lens);
            ray.origin = origin_ + (right_ * d.x + up_ * d.y) * lens_radius_;
            ray.dir = focus - ray.origin;
        }
        ray.dir = normalize(ray.dir);
    }
    ray.time = shutter_open_ + (shutter_close_ - shutter_open_) * time_u;
    return ray;
}

}  // namespace sahara
