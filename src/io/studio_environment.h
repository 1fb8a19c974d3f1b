#pragma once
/// The built-in environment of `sahara view`: a photo studio generated in code
/// as a lat-long image, so that it is importance-sampled like any envmap and
/// metals and glossy surfaces have something to reflect.
#include <memory>

#include "desc/scene_desc.h"

namespace sahara {

/// The studio around `up` as a lat-long image (2:1, `width` pixels wide) in the
/// mapping of math/latlong.h: a bright soft overhead area, a sky-to-wall
/// gradient with panel seams near the horizon, a darker floor, a large key
/// softbox front-left of `toward_viewer` and a strip light behind on the right.
/// `toward_viewer` is any direction not parallel to `up`.
std::shared_ptr<const Image> make_studio_environment(const Vec3& up, const Vec3& toward_viewer,
                                                     int width = 512);

/// A background that shows `image` (lat-long around `up`) and lights the scene with it.
BackgroundDesc envmap_background(std::shared_ptr<const Image> image, const Vec3& up, float strength,
                                 const std::string& file);

}  // namespace sahara
