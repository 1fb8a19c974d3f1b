#pragma once
/// Writing a render's image with its metadata, and reading one back to resume.
/// EXR files also carry the film's exact state (per-pixel double sums as raw
/// bit patterns, and counts) in uint32 channels, so a resumed render continues
/// bit for bit where the first stopped.
#include <filesystem>
#include <optional>
#include <string>

#include "io/image_io.h"
#include "render/bvh_cost.h"
#include "render/film.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace sahara {

/// What must match between a file and a render for --resume to continue it.
ImageMetadata render_identity(const Scene& scene);

/// Full metadata of a render: identity plus spp, time, version, state.
ImageMetadata render_metadata(const Scene& scene, const Film& film, const RenderResult& result,
                              double total_render_seconds);

/// Writes `film` to `file` (tone-mapped for 8-bit formats, with `exposure`
/// replacing the scene's when given; with state channels for EXR). Atomic
/// (temporary + rename). Returns how many pixels the tone curve clipped.
size_t write_render(const std::filesystem::path& file, const Scene& scene, const Film& film,
                    const ImageMetadata& metadata, std::optional<float> exposure = std::nullopt);

/// Draws the legend labels of a bvh-cost image into its pixels with a TrueType
/// font (through the image codec; render draws no text). Returns a warning
/// (empty: none), e.g. that no font was found and the legend has no text.
/// Throws InputError naming `file` if the codec cannot be loaded.
std::string draw_bvh_cost_legend(BvhCostImage& image, const std::filesystem::path& file);

/// Loads the state of a sahara EXR into `film` after checking that it was
/// rendered with the same scene and settings. Returns the render seconds the
/// file records. Throws InputError naming the file and the mismatch.
double resume_film(const std::filesystem::path& file, const Scene& scene, Film& film);

/// A stable fingerprint of a scene file's bytes ("-" for the built-in scene).
std::string scene_fingerprint(const std::string& source);

/// Human name of a stop reason ("complete", "interrupted", ...).
const char* stop_reason_name(StopReason r);

}  // namespace sahara
