#pragma once
/// From scene radiance to display values in [0,1] for 8-bit outputs: exposure
/// (stops) then a tone curve, per channel. HDR outputs stay linear and unclipped.
///
/// Curves: clamp (identity, clipped at 1), reinhard (v / (1 + v); Reinhard et
/// al. 2002), aces (Narkowicz 2015 fit of the ACES RRT+ODT), filmic (Hable's
/// 2010 "Uncharted 2" curve with its published constants, exposure bias 2 and
/// linear white 11.2). All map 0 to 0, are non-decreasing and stay in [0,1].
#include <optional>
#include <string_view>
#include <vector>

#include "desc/scene_desc.h"

namespace sahara {

/// Applies the tone curve (no exposure) to one linear value; NaN and negatives give 0.
float tonemap_value(float v, Tonemap curve);

/// Whether the curve saturates at `v` (its display value reached 1, detail is lost).
bool tonemap_clips(float v, Tonemap curve);

/// Returns display-referred linear RGB in [0,1] (3 floats per pixel); counts
/// clipped pixels (any channel saturated by the curve after exposure) into
/// *clipped when given.
std::vector<float> tonemap_image(const std::vector<float>& rgb, float exposure_stops, Tonemap curve,
                                 size_t* clipped = nullptr);

/// Exposure in stops that maps the image's log-average luminance to middle grey
/// 0.18 (the "key value" of Reinhard et al. 2002, "Photographic Tone
/// Reproduction for Digital Images"). Pixels without light (luminance 0) or
/// non-finite ones are left out, so a black background does not brighten the
/// rest; an image with no light gives 0. The result is limited to [-32, 32].
float auto_exposure_stops(const std::vector<float>& rgb);

/// The scene-format name of a curve ("clamp", "reinhard", "aces", "filmic").
std::string_view tonemap_name(Tonemap curve);
/// Parses a scene-format curve name; nullopt when unknown.
std::optional<Tonemap> tonemap_from_name(std::string_view name);

}  // namespace sahara
