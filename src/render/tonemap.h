#pragma once
/// From scene radiance to display values in [0,1] for 8-bit outputs: exposure
/// (stops) then a tone curve. HDR outputs stay linear and unclipped.
#include <vector>

#include "scene/scene_desc.h"

namespace sahara {

/// Applies exposure and the tone curve to one linear value.
float tonemap_value(float v, Tonemap curve);

/// Returns display-referred linear RGB in [0,1]; counts clipped pixels (any
/// channel above 1 before clamping) into *clipped when given.
std::vector<float> tonemap_image(const std::vector<float>& rgb, float exposure_stops, Tonemap curve,
                                 size_t* clipped = nullptr);

}  // namespace sahara
