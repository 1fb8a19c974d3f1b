#pragma once
/// Piecewise-constant 1-D and 2-D distributions for importance sampling
/// (light selection by power, environment maps by luminance), built by
/// inverting the cumulative distribution function (pbrt, "Sampling Random
/// Variables"). CDFs are accumulated in double so that long tables stay exact.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "math/vec3.h"

namespace sahara {

/// A distribution over n bins of [0,1) proportional to non-negative weights.
class Distribution1D {
   public:
    Distribution1D() = default;
    /// Weights must be finite and >= 0; all zero gives the uniform distribution.
    explicit Distribution1D(std::vector<float> weights) : func_(std::move(weights)) {
        const size_t n = func_.size();
        cdf_.assign(n + 1, 0.0f);
        double sum = 0;
        for (float w : func_) sum += double(std::max(w, 0.0f));
        if (sum <= 0) {
            std::fill(func_.begin(), func_.end(), 1.0f);
            sum = double(n);
        }
        double acc = 0;
        for (size_t i = 0; i < n; ++i) {
            func_[i] = std::max(func_[i], 0.0f);
            acc += double(func_[i]);
            cdf_[i + 1] = float(acc / sum);
        }
        if (n > 0) cdf_[n] = 1.0f;
        sum_ = sum;
    }

    size_t size() const { return func_.size(); }
    bool empty() const { return func_.empty(); }
    /// Sum of the weights.
    double sum() const { return sum_; }
    /// Probability of bin i when sampling discretely.
    float pmf(size_t i) const { return float(double(func_[i]) / sum_); }
    /// Density (with respect to [0,1)) inside bin i when sampling continuously.
    float density(size_t i) const { return float(double(func_[i]) * double(func_.size()) / sum_); }

    /// Picks bin i with probability pmf(i); `u_remapped` is u rescaled to [0,1) within the bin.
    size_t sample_discrete(float u, float* pmf_out = nullptr, float* u_remapped = nullptr) const {
        const size_t i = find_bin(u);
        if (pmf_out) *pmf_out = pmf(i);
        if (u_remapped) {
            const float width = cdf_[i + 1] - cdf_[i];
            *u_remapped = width > 0 ? std::min((u - cdf_[i]) / width, 0x1.fffffep-1f) : 0.0f;
        }
        return i;
    }
    /// A point in [0,1) distributed proportionally to the piecewise-constant function.
    float sample_continuous(float u, float* pdf_out, size_t* bin = nullptr) const {
        const size_t i = find_bin(u);
        const float width = cdf_[i + 1] - cdf_[i];
        const float du = width > 0 ? (u - cdf_[i]) / width : 0.0f;
        if (pdf_out) *pdf_out = density(i);
        if (bin) *bin = i;
        return std::min((float(i) + du) / float(func_.size()), 0x1.fffffep-1f);
    }

   private:
    size_t find_bin(float u) const {
        // The first cdf entry greater than u ends the bin; zero-weight bins
        // have equal neighbouring cdf entries and are never chosen.
        const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
        const size_t i = size_t(std::max<std::ptrdiff_t>(it - cdf_.begin() - 1, 0));
        return std::min(i, func_.size() - 1);
    }

    std::vector<float> func_, cdf_;
    double sum_ = 0;
};

/// A distribution over [0,1)^2 on a width x height grid of cells: a marginal
/// over rows and one conditional distribution per row.
class Distribution2D {
   public:
    Distribution2D() = default;
    /// `weights` is row-major, width * height values.
    Distribution2D(const std::vector<float>& weights, int width, int height)
        : width_(width), height_(height) {
        std::vector<float> row_sums(size_t(height), 0.0f);
        rows_.reserve(size_t(height));
        for (int y = 0; y < height; ++y) {
            const auto first = weights.begin() + std::ptrdiff_t(y) * width;
            double sum = 0;  // before the row turns an all-zero row uniform
            for (auto it = first; it != first + width; ++it) sum += double(std::max(*it, 0.0f));
            row_sums[size_t(y)] = float(sum);
            rows_.emplace_back(std::vector<float>(first, first + width));
        }
        marginal_ = Distribution1D(std::move(row_sums));
    }

    bool empty() const { return rows_.empty(); }
    /// Samples (u, v) in [0,1)^2; pdf with respect to area in the unit square.
    Vec2 sample(Vec2 u, float* pdf) const {
        float pdf_v = 0, pdf_u = 0;
        size_t row = 0;
        const float v = marginal_.sample_continuous(u.y, &pdf_v, &row);
        const float uu = rows_[row].sample_continuous(u.x, &pdf_u);
        *pdf = pdf_v * pdf_u;
        return {uu, v};
    }
    /// Density at (u, v) with respect to area in the unit square.
    float pdf(Vec2 uv) const {
        const int x = std::clamp(int(uv.x * float(width_)), 0, width_ - 1);
        const int y = std::clamp(int(uv.y * float(height_)), 0, height_ - 1);
        return marginal_.density(size_t(y)) * rows_[size_t(y)].density(size_t(x));
    }

   private:
    int width_ = 0, height_ = 0;
    std::vector<Distribution1D> rows_;
    Distribution1D marginal_;
};

}  // namespace sahara
