#include "render/film.h"

namespace sahara {

Film::Film(int width, int height)
    : width_(width),
      height_(height),
      sum_(size_t(width) * size_t(height)),
      sum_sq_(size_t(width) * size_t(height), 0.0),
      count_(size_t(width) * size_t(height), 0u) {}

Rgb Film::mean(int x, int y) const {
    const size_t i = size_t(y) * size_t(width_) + size_t(x);
    if (count_[i] == 0) return Rgb(0.0f);
    return Rgb(sum_[i] / double(count_[i]));
}

double Film::luminance_variance(int x, int y) const {
    const size_t i = size_t(y) * size_t(width_) + size_t(x);
    const double n = count_[i];
    if (n < 2) return 0;
    const Vec3d s = sum_[i];
    const double mean_l = (0.2126 * s.x + 0.7152 * s.y + 0.0722 * s.z) / n;
    return std::max(0.0, (sum_sq_[i] / n - mean_l * mean_l) * n / (n - 1));
}

std::vector<float> Film::to_rgb() const {
    std::vector<float> out(size_t(width_) * size_t(height_) * 3);
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
            Rgb m = mean(x, y);
            float* p = &out[(size_t(y) * size_t(width_) + size_t(x)) * 3];
            p[0] = m.x;
            p[1] = m.y;
            p[2] = m.z;
        }
    return out;
}

}  // namespace sahara
