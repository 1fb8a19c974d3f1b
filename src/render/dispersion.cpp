#include "render/dispersion.h"

#include <algorithm>

namespace sahara {

namespace {

/// The shortest wavelength of each channel's band (nm); each is 100 nm wide.
constexpr float kBandStart[3] = {600.0f, 500.0f, 400.0f};
constexpr float kBandWidth = 100.0f;

}  // namespace

float dispersed_ior(float ior, float dispersion, float wavelength_nm) {
    if (!(dispersion > 0.0f)) return ior;
    const float abbe = 20.0f / dispersion;
    const float n = ior + (ior - 1.0f) / abbe * (523655.0f / (wavelength_nm * wavelength_nm) - 1.5168f);
    return std::max(n, 1.0f);
}

PathWavelength sample_path_wavelength(float u) {
    const float scaled = std::clamp(u, 0.0f, 0x1.fffffep-1f) * 3.0f;
    PathWavelength w;
    w.channel = std::min(int(scaled), 2);
    w.nm = kBandStart[w.channel] + kBandWidth * (scaled - float(w.channel));
    return w;
}

}  // namespace sahara
