#pragma once
/// Camera: both scene-format camera forms (look-at + vfov, and the "20 minutes"
/// Euler + focal length form) and glTF cameras reduce to one basis here.
#include "math/ray.h"
#include "desc/scene_desc.h"

namespace sahara {

class Camera {
   public:
    Camera(const CameraDesc& desc, int width, int height);

    /// Ray through continuous pixel position (px, py) (0,0 = top-left corner of
    /// the image), lens sample in [0,1)^2 and shutter sample in [0,1).
    Ray generate_ray(float px, float py, Vec2 lens, float time_u) const;

    bool has_lens() const { return lens_radius_ > 0; }
    bool has_shutter() const { return shutter_close_ > shutter_open_; }
    const Vec3& position() const { return origin_; }
    const Vec3& forward() const { return forward_; }

   private:
    Vec3 origin_, forward_, right_, up_;
    float half_w_ = 1, half_h_ = 1;  ///< view plane half extents at distance 1
    int width_, height_;
    bool ortho_ = false;
    float lens_radius_ = 0, focus_distance_ = 1;
    float shutter_open_ = 0, shutter_close_ = 0;
};

}  // namespace sahara
