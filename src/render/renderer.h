#pragma once
/// The render loop: image tiles over OpenMP threads (dynamic scheduling),
/// samples in progressive passes. Every pixel keeps its own sample count and
/// takes its samples in index order, so the film is a valid image whenever the
/// render stops (at pixel granularity), and continuing a stopped film later
/// adds exactly the samples a single run would have added.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "render/film.h"
#include "scene/scene.h"

namespace sahara {

class RenderSession;

struct RenderOptions {
    int threads = 0;        ///< 0 = all hardware threads
    bool progress = false;  ///< draw progress on stderr
    /// Set by someone else (signal handler, preview window) to stop early; polled per pixel.
    const std::atomic<bool>* stop = nullptr;
    /// Called on the thread that called run() about every tick_seconds while the
    /// workers render (preview, checkpoints). Keep it short.
    std::function<void(RenderSession&)> on_tick = nullptr;
    double tick_seconds = 1.0 / 30.0;
};

/// Why a render ended.
enum class StopReason : uint8_t { complete, converged, time_limit, interrupted };

struct RenderResult {
    double seconds = 0;
    uint64_t samples = 0;  ///< camera samples taken in this run
    int spp_done = 0;      ///< samples per pixel completed in every pixel
    int spp_max = 0;       ///< most samples in any pixel
    double spp_mean = 0;
    uint64_t nonfinite = 0;  ///< NaN/Inf samples discarded (film total)
    StopReason stop = StopReason::complete;
};

/// Edge length of a square render tile in pixels.
inline constexpr int kTileSize = 16;
/// Adaptive sampling renders this many samples everywhere before trusting variance estimates.
inline constexpr int kAdaptiveMinSpp = 16;

struct TileRect {
    int x0, y0, x1, y1;
};

/// One render of a scene into a film. run() renders on worker threads while
/// the calling thread watches the clock, the stop flag and calls on_tick; the
/// other members are for on_tick (or any thread) while the render runs.
class RenderSession {
   public:
    RenderSession(const Scene& scene, Film& film, RenderOptions options);
    ~RenderSession();

    /// Renders until every pixel has scene.render.spp samples, the estimated
    /// error reaches scene.render.target_error, the time limit passes or a stop
    /// is requested. The film may already hold samples (resume).
    RenderResult run();

    /// Stops at the next pixel; the film stays a valid image.
    void request_stop(StopReason reason = StopReason::interrupted);
    double elapsed_seconds() const;
    /// Estimated seconds to the end (time limit included), < 0 when unknown.
    double eta_seconds() const;
    int spp_target() const { return scene_.render.spp; }
    /// Every pixel has at least this many samples (updated after each pass).
    int spp_complete() const { return spp_complete_.load(); }
    /// The sample count the current pass brings pixels to (0 during adaptive passes).
    int pass_target() const { return pass_target_.load(); }
    uint64_t samples_taken() const { return samples_.load(); }
    /// The film being rendered: read it only inside visit_changed_tiles.
    const Film& film() const { return film_; }

    size_t tile_count() const { return tiles_.size(); }
    const TileRect& tile(size_t i) const { return tiles_[i]; }
    /// Calls fn for each tile that changed since seen[i] (updated); tiles being
    /// rendered are skipped unless `wait`. fn may read the film inside the tile.
    void visit_changed_tiles(std::vector<uint64_t>& seen, bool wait,
                             const std::function<void(const TileRect&)>& fn);
    /// A consistent copy of the film (waits for each tile in flight).
    void snapshot(Film& out);

   private:
    void render_all();
    void run_pass(const std::vector<uint32_t>* targets, uint32_t uniform_target);
    uint64_t render_tile(size_t tile, const std::vector<uint32_t>* targets, uint32_t uniform_target);
    bool adaptive_round();

    const Scene& scene_;
    Film& film_;
    RenderOptions options_;
    int threads_;
    std::vector<TileRect> tiles_;
    std::vector<std::mutex> tile_locks_;
    std::vector<std::atomic<uint64_t>> tile_generation_;
    std::atomic<bool> stop_{false};
    std::atomic<int> stop_reason_{int(StopReason::complete)};
    std::atomic<int> spp_complete_{0}, pass_target_{0};
    std::atomic<uint64_t> samples_{0};
    uint64_t samples_planned_ = 1;  ///< for the ETA: samples a complete run takes
    std::unique_ptr<class Progress> progress_;
    std::chrono::steady_clock::time_point start_;
};

/// Renders scene.render.spp samples per pixel into `film` (which must match
/// the scene's resolution), honouring time limit and target error.
RenderResult render_image(const Scene& scene, Film& film, const RenderOptions& options);

/// Renders samples [sample_begin, sample_end) of every pixel into `film`.
void render_pass(const Scene& scene, Film& film, int sample_begin, int sample_end, int threads,
                 class Progress* progress);

/// Per-pixel relative standard error of the luminance mean,
/// sqrt(Var[mean] / (mean^2 + 0.01)) — the relMSE convention, so dark pixels
/// are not held to an impossible relative standard. 0 for pixels with < 2 samples.
std::vector<float> relative_error_map(const Film& film);
/// Root mean square of relative_error_map: the image's estimated error.
double estimated_relative_error(const Film& film);
/// The same metric measured against a reference image (linear RGB, same size).
double relative_error_to(const Film& film, const std::vector<float>& reference_rgb);

/// Smallest sample count of any pixel.
uint32_t min_sample_count(const Film& film);

/// Takes samples [begin, end) of image pixel (x, y), in index order, into pixel
/// (fx, fy) of `film` (which may be a tile-sized film: distributed rendering).
void render_pixel_samples(const Scene& scene, const class Camera& camera, Film& film, class Sampler& sampler,
                          int x, int y, int fx, int fy, uint32_t begin, uint32_t end);

/// The per-pixel sample targets of the next adaptive-sampling round: pixels
/// whose (3x3-smoothed) estimated error exceeds `target_error` get as many more
/// samples as the 1/sqrt(n) law says they need, at most doubling, capped at
/// `cap`. Returns false when no pixel needs more.
bool adaptive_sample_targets(const Film& film, double target_error, uint32_t cap,
                             std::vector<uint32_t>& targets);

}  // namespace sahara
