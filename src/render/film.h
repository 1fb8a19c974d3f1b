#pragma once
/// Accumulates radiance samples per pixel. Each pixel is written by exactly one
/// thread at a time (tiles), so no atomics are needed and summation order is
/// fixed: the image does not depend on the thread count.
#include <atomic>
#include <cstdint>
#include <vector>

#include "math/vec3.h"

namespace sahara {

class Film {
   public:
    Film(int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }

    /// Adds one sample to pixel (x, y). Non-finite samples are counted and dropped.
    void add_sample(int x, int y, const Rgb& value) {
        const size_t i = size_t(y) * size_t(width_) + size_t(x);
        if (!is_finite(value)) {
            nonfinite_.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        sum_[i] += Vec3d(value);
        sum_sq_[i] += double(luminance(value)) * double(luminance(value));
    }
    /// Records that pixel (x, y) has received `n` more sample attempts.
    void add_count(int x, int y, uint32_t n) { count_[size_t(y) * size_t(width_) + size_t(x)] += n; }

    /// Mean radiance of pixel (x, y) (0 if it has no samples).
    Rgb mean(int x, int y) const;
    uint32_t count(int x, int y) const { return count_[size_t(y) * size_t(width_) + size_t(x)]; }
    /// Sample variance of the pixel's luminance (0 with fewer than 2 samples).
    double luminance_variance(int x, int y) const;
    /// All pixel means, row-major RGB (width * height * 3 floats).
    std::vector<float> to_rgb() const;
    uint64_t nonfinite_samples() const { return nonfinite_.load(); }

    /// Exact accumulator state of pixel (x, y), for checkpoints and --resume.
    const Vec3d& sum(int x, int y) const { return sum_[size_t(y) * size_t(width_) + size_t(x)]; }
    double sum_sq(int x, int y) const { return sum_sq_[size_t(y) * size_t(width_) + size_t(x)]; }
    /// Replaces pixel (x, y)'s accumulator state (restoring a checkpoint).
    void set_pixel_state(int x, int y, const Vec3d& sum, double sum_sq, uint32_t count) {
        const size_t i = size_t(y) * size_t(width_) + size_t(x);
        sum_[i] = sum;
        sum_sq_[i] = sum_sq;
        count_[i] = count;
    }
    /// Adds to the discarded-sample count (restoring a checkpoint).
    void add_nonfinite(uint64_t n) { nonfinite_.fetch_add(n); }

   private:
    int width_, height_;
    std::vector<Vec3d> sum_;  // double: sums of millions of samples stay exact enough
    std::vector<double> sum_sq_;
    std::vector<uint32_t> count_;
    std::atomic<uint64_t> nonfinite_{0};
};

}  // namespace sahara
