#pragma once
/// The render loop: image tiles over OpenMP threads (dynamic scheduling),
/// samples in progressive passes so that an image of the samples done so far
/// is always valid.
#include <cstdint>

#include "render/film.h"
#include "scene/scene.h"

namespace sahara {

struct RenderOptions {
    int threads = 0;        ///< 0 = all hardware threads
    bool progress = false;  ///< draw progress on stderr
};

struct RenderResult {
    double seconds = 0;
    uint64_t samples = 0;        ///< camera samples taken
    int spp_done = 0;            ///< samples per pixel completed in every pixel
    uint64_t nonfinite = 0;      ///< NaN/Inf samples discarded
};

/// Edge length of a square render tile in pixels.
inline constexpr int kTileSize = 16;

/// Renders scene.render.spp samples per pixel into `film` (which must match
/// the scene's resolution).
RenderResult render_image(const Scene& scene, Film& film, const RenderOptions& options);

/// Renders samples [sample_begin, sample_end) of every pixel into `film`.
void render_pass(const Scene& scene, Film& film, int sample_begin, int sample_end, int threads,
                 class Progress* progress);

}  // namespace sahara
