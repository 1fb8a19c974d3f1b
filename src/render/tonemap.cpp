#include "render/tonemap.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace sahara {

namespace {

/// Narkowicz's 2015 fit of the ACES reference rendering transform (unclamped).
float aces_fit(float v) {
    const float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
    return (v * (a * v + b)) / (v * (c * v + d) + e);
}

/// Hable's filmic curve (GDC 2010, "Uncharted 2: HDR Lighting"): shoulder
/// strength A, linear strength B, linear angle C, toe strength D, toe
/// numerator E, toe denominator F. The published form N(x)/D(x) - E/F is
/// rewritten over a common denominator, x (A(F-E) x + B(CF-E)) / (F D(x)), so
/// that it is exactly 0 at 0 and has no cancellation for small x.
float hable(float x) {
    const float a = 0.15f, b = 0.50f, c = 0.10f, d = 0.20f, e = 0.02f, f = 0.30f;
    return x * (a * (f - e) * x + b * (c * f - e)) / (f * (x * (a * x + b) + d * f));
}

/// The curve before the final clamp to [0,1]; v is finite and > 0.
float curve_unclamped(float v, Tonemap curve) {
    switch (curve) {
        case Tonemap::clamp:
            return v;
        case Tonemap::reinhard:
            return v / (1.0f + v);
        case Tonemap::aces:
            return aces_fit(v);
        case Tonemap::filmic: {
            const float exposure_bias = 2.0f, linear_white = 11.2f;
            return hable(exposure_bias * v) / hable(linear_white);
        }
    }
    return v;
}

constexpr std::array<std::pair<Tonemap, std::string_view>, 4> kNames{{
    {Tonemap::clamp, "clamp"},
    {Tonemap::reinhard, "reinhard"},
    {Tonemap::aces, "aces"},
    {Tonemap::filmic, "filmic"},
}};

}  // namespace

float tonemap_value(float v, Tonemap curve) {
    if (!(v > 0.0f)) return 0.0f;  // negatives and NaN
    if (std::isinf(v)) return 1.0f;
    return std::clamp(curve_unclamped(v, curve), 0.0f, 1.0f);
}

bool tonemap_clips(float v, Tonemap curve) {
    if (!(v > 0.0f)) return false;
    if (std::isinf(v)) return true;
    return curve_unclamped(v, curve) > 1.0f;
}

std::vector<float> tonemap_image(const std::vector<float>& rgb, float exposure_stops, Tonemap curve,
                                 size_t* clipped) {
    const float scale = std::exp2(exposure_stops);
    std::vector<float> out(rgb.size());
    size_t n_clipped = 0;
    for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
        bool clip = false;
        for (size_t c = 0; c < 3; ++c) {
            const float v = rgb[i + c] * scale;
            clip |= tonemap_clips(v, curve);
            out[i + c] = tonemap_value(v, curve);
        }
        n_clipped += clip;
    }
    if (clipped) *clipped = n_clipped;
    return out;
}

float auto_exposure_stops(const std::vector<float>& rgb) {
    // Sum of logs in double: millions of pixels would lose digits in float.
    double log_sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
        const float lum = luminance(Rgb(rgb[i], rgb[i + 1], rgb[i + 2]));
        if (!(lum > 0.0f) || !std::isfinite(lum)) continue;
        log_sum += std::log(double(lum));
        ++n;
    }
    if (n == 0) return 0.0f;
    const double log_average = log_sum / double(n);
    const double stops = (std::log(0.18) - log_average) / std::log(2.0);
    return float(std::clamp(stops, -32.0, 32.0));
}

std::string_view tonemap_name(Tonemap curve) {
    for (const auto& [c, name] : kNames)
        if (c == curve) return name;
    return "clamp";
}

std::optional<Tonemap> tonemap_from_name(std::string_view name) {
    for (const auto& [c, n] : kNames)
        if (n == name) return c;
    return std::nullopt;
}

}  // namespace sahara
