#include "io/studio_environment.h"

#include <algorithm>
#include <cmath>

#include "math/latlong.h"

namespace sahara {

namespace {

float smoothstep(float e0, float e1, float x) {
    const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

float degrees(float rad) { return rad * (180.0f / kPi); }

/// A rectangle of light in (azimuth, elevation) degrees with soft edges; 1 inside.
struct Softbox {
    float azimuth, elevation, width, height;
    Rgb radiance;
    float weight(float az, float el) const {
        float da = std::abs(az - azimuth);
        da = std::min(da, 360.0f - da);
        constexpr float kEdge = 4.0f;  // degrees of falloff: soft reflections, no aliasing
        return smoothstep(0.5f * width + kEdge, 0.5f * width, da) *
               smoothstep(0.5f * height + kEdge, 0.5f * height, std::abs(el - elevation));
    }
};

/// Azimuth 0 points at the viewer (whose camera sits near +37 degrees); positive
/// azimuths turn towards the viewer's right. The key lights from the front left.
constexpr Softbox kKey{-45.0f, 35.0f, 34.0f, 26.0f, Rgb(20.0f, 19.0f, 17.5f)};
constexpr Softbox kStrip{140.0f, 20.0f, 12.0f, 44.0f, Rgb(10.0f, 10.5f, 11.0f)};

/// Radiance of the studio in a direction at azimuth `az` and elevation `el` (degrees).
Rgb studio_radiance(float az, float el) {
    Rgb c;
    if (el >= 0) {
        // Walls lighter near the horizon, a soft seam every 30 degrees so that a
        // reflection shows the turn of a surface; then the overhead area.
        const float seam = smoothstep(1.5f, 0.0f, std::abs(std::remainder(az, 30.0f)));
        const float wall = (0.3f + 0.25f * (1.0f - el / 90.0f)) * (el < 25.0f ? 1.0f - 0.35f * seam : 1.0f);
        c = Rgb(0.95f, 0.97f, 1.0f) * wall;
        c = c + Rgb(2.5f, 2.5f, 2.4f) * smoothstep(50.0f, 70.0f, el);
    } else {
        // Floor: a clear horizon line, then darker towards the nadir.
        c = Rgb(0.22f, 0.20f, 0.18f) * (0.45f + 0.55f * smoothstep(-90.0f, -5.0f, el));
    }
    c = c + kKey.radiance * kKey.weight(az, el) + kStrip.radiance * kStrip.weight(az, el);
    return c;
}

}  // namespace

std::shared_ptr<const Image> make_studio_environment(const Vec3& up, const Vec3& toward_viewer, int width) {
    const Vec3 u = normalize(up);
    const Vec3 front = normalize(toward_viewer - u * dot(toward_viewer, u));
    const Vec3 right = cross(u, front);  // the viewer's right
    auto img = std::make_shared<Image>();
    img->width = std::max(width, 8);
    img->height = img->width / 2;
    img->rgba.resize(size_t(img->width) * size_t(img->height) * 4);
    for (int y = 0; y < img->height; ++y) {
        for (int x = 0; x < img->width; ++x) {
            float sin_theta = 0;
            const Vec2 uv((float(x) + 0.5f) / float(img->width), (float(y) + 0.5f) / float(img->height));
            const Vec3 d = envmap_direction(u, uv, &sin_theta);
            const float az = degrees(std::atan2(dot(d, right), dot(d, front)));
            const float el = degrees(std::asin(std::clamp(dot(d, u), -1.0f, 1.0f)));
            const Rgb c = studio_radiance(az, el);
            float* p = &img->rgba[(size_t(y) * size_t(img->width) + size_t(x)) * 4];
            p[0] = c.x, p[1] = c.y, p[2] = c.z, p[3] = 1.0f;
        }
    }
    return img;
}

BackgroundDesc envmap_background(std::shared_ptr<const Image> image, const Vec3& up, float strength,
                                 const std::string& file) {
    BackgroundDesc bg;
    bg.type = BackgroundDesc::Type::envmap;
    bg.up = normalize(up);
    bg.strength = strength;
    bg.file = file;
    bg.image = std::move(image);
    return bg;
}

}  // namespace sahara
