#include "render/renderer.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <thread>

#include "base/counters.h"
#include "render/camera.h"
#include "render/integrator.h"
#include "render/progress.h"
#include "render/sampler.h"

namespace sahara {

using Clock = std::chrono::steady_clock;

namespace {

/// Largest progressive pass: bigger passes amortise nothing more and make the preview stale.
constexpr int kMaxPassSpp = 64;
/// Added to mean^2 in the relative error (the relMSE convention).
constexpr double kRelErrorEpsilon = 0.01;

double luminance_d(const Vec3d& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

/// Takes samples [begin, end) of pixel (x, y), in index order.
void render_pixel(const Scene& scene, const Camera& camera, Film& film, Sampler& sampler, int x, int y,
                  uint32_t begin, uint32_t end) {
    render_pixel_samples(scene, camera, film, sampler, x, y, x, y, begin, end);
}

/// Whether camera rays are traced as packets: the path integrator (which can
/// take a first hit), where the scene says packets are faster than single rays
/// (Scene::packets_pay_off), unless --no-packets (RenderSettings::packets).
bool use_packets(const Scene& scene) {
    return scene.render.packets && scene.render.integrator == IntegratorType::path && scene.packets_pay_off();
}

/// Takes samples [begin[i], end[i]) of the pixels of the block of up to 4x4
/// pixels at (x0, y0) (lane i = pixel (x0 + i % 4, y0 + i / 4), only those
/// inside `r`). The camera rays of one sample index go through the scene as
/// one packet; each pixel's sampler stream and sample order are those of
/// render_pixel_samples, so the image is bit-identical to single rays.
uint64_t render_block(const Scene& scene, const Camera& camera, Film& film, Sampler& sampler, int x0, int y0,
                      const uint32_t begin[kPacketSize], const uint32_t end[kPacketSize]) {
    uint32_t lo = ~0u, hi = 0;
    uint64_t taken = 0;
    for (int i = 0; i < kPacketSize; ++i)
        if (end[i] > begin[i])
            lo = std::min(lo, begin[i]), hi = std::max(hi, end[i]), taken += end[i] - begin[i];
    Ray rays[kPacketSize];
    for (uint32_t s = lo; s < hi; ++s) {
        RayPacket packet;
        for (int i = 0; i < kPacketSize; ++i) {
            if (s < begin[i] || s >= end[i]) continue;
            const int x = x0 + i % 4, y = y0 + i / 4;
            sampler.start(uint32_t(x), uint32_t(y), s);
            const Vec2 jitter = sampler.next_2d();
            const Vec2 lens = sampler.next_2d();
            const float time_u = sampler.next_1d();
            rays[i] = camera.generate_ray(float(x) + jitter.x, float(y) + jitter.y, lens, time_u);
            packet.set(i, rays[i]);
            count_ray(RayKind::camera);
        }
        HitPacket hits;
        scene.intersect_packet(packet, hits);
        for (uint32_t m = packet.active; m; m &= m - 1) {
            const int i = __builtin_ctz(m);
            const int x = x0 + i % 4, y = y0 + i / 4;
            // Replay the camera dimensions so the path continues the pixel's own stream.
            sampler.start(uint32_t(x), uint32_t(y), s);
            sampler.next_2d();
            sampler.next_2d();
            sampler.next_1d();
            const Hit first = hits.hit(i);
            film.add_sample(x, y,
                            path_trace_first_hit(scene, rays[i], &first, sampler, scene.render.max_depth));
        }
    }
    for (int i = 0; i < kPacketSize; ++i)
        if (end[i] > begin[i]) film.add_count(x0 + i % 4, y0 + i / 4, end[i] - begin[i]);
    return taken;
}

/// Renders tile `r` in 4x4 blocks; `range(x, y, begin, end)` gives each pixel's
/// samples; stops between blocks when `stop` is set. Returns the samples taken.
template <class RangeFn>
uint64_t render_tile_packets(const Scene& scene, const Camera& camera, Film& film, Sampler& sampler,
                             const TileRect& r, RangeFn&& range, const std::atomic<bool>* stop) {
    uint64_t taken = 0;
    for (int y0 = r.y0; y0 < r.y1; y0 += 4)
        for (int x0 = r.x0; x0 < r.x1; x0 += 4) {
            if (stop && stop->load(std::memory_order_relaxed)) return taken;
            uint32_t begin[kPacketSize] = {}, end[kPacketSize] = {};
            for (int i = 0; i < kPacketSize; ++i) {
                const int x = x0 + i % 4, y = y0 + i / 4;
                if (x < r.x1 && y < r.y1) range(x, y, begin[i], end[i]);
            }
            taken += render_block(scene, camera, film, sampler, x0, y0, begin, end);
        }
    return taken;
}

std::vector<TileRect> make_tiles(int w, int h) {
    std::vector<TileRect> tiles;
    for (int y0 = 0; y0 < h; y0 += kTileSize)
        for (int x0 = 0; x0 < w; x0 += kTileSize)
            tiles.push_back({x0, y0, std::min(x0 + kTileSize, w), std::min(y0 + kTileSize, h)});
    return tiles;
}

}  // namespace

void render_pixel_samples(const Scene& scene, const Camera& camera, Film& film, Sampler& sampler, int x,
                          int y, int fx, int fy, uint32_t begin, uint32_t end) {
    // A pinhole camera ignores the lens sample, and the shutter time matters only
    // when a sphere moves (nothing else depends on time; a closed or reversed
    // shutter is left alone). Unused dimensions are skipped rather than drawn:
    // every later dimension, and so the image, is unchanged.
    const bool want_lens = camera.has_lens();
    const bool want_time = scene.features.has_motion || scene.features.forced_all ||
                           scene.camera.shutter_close < scene.camera.shutter_open;
    for (uint32_t s = begin; s < end; ++s) {
        sampler.start(uint32_t(x), uint32_t(y), s);
        const Vec2 jitter = sampler.next_2d();
        Vec2 lens{0.5f, 0.5f};
        if (want_lens)
            lens = sampler.next_2d();
        else
            sampler.skip_2d();
        float time_u = 0.0f;
        if (want_time)
            time_u = sampler.next_1d();
        else
            sampler.skip_1d();
        const Ray ray = camera.generate_ray(float(x) + jitter.x, float(y) + jitter.y, lens, time_u);
        count_ray(RayKind::camera);
        film.add_sample(fx, fy, estimate_radiance(scene, ray, sampler, scene.render.max_depth));
    }
    if (end > begin) film.add_count(fx, fy, end - begin);
}

void render_pass(const Scene& scene, Film& film, int sample_begin, int sample_end, int threads,
                 Progress* progress) {
    const Camera camera(scene.camera, film.width(), film.height());
    const std::vector<TileRect> tiles = make_tiles(film.width(), film.height());
    const bool packets = use_packets(scene);
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(dynamic, 1) nowait
        for (size_t t = 0; t < tiles.size(); ++t) {
            Sampler sampler(scene.render.seed, scene.render.sampler);
            const TileRect& r = tiles[t];
            if (packets) {
                render_tile_packets(
                    scene, camera, film, sampler, r,
                    [&](int, int, uint32_t& b, uint32_t& e) {
                        b = uint32_t(sample_begin), e = uint32_t(sample_end);
                    },
                    nullptr);
            } else {
                for (int y = r.y0; y < r.y1; ++y)
                    for (int x = r.x0; x < r.x1; ++x)
                        render_pixel(scene, camera, film, sampler, x, y, uint32_t(sample_begin),
                                     uint32_t(sample_end));
            }
            const uint64_t n =
                uint64_t(r.x1 - r.x0) * uint64_t(r.y1 - r.y0) * uint64_t(sample_end - sample_begin);
            if (progress) progress->advance(n, n);
        }
        flush_thread_counters();
    }
}

RenderSession::RenderSession(const Scene& scene, Film& film, RenderOptions options)
    : scene_(scene),
      film_(film),
      options_(std::move(options)),
      threads_(options_.threads > 0 ? options_.threads : omp_get_max_threads()),
      tiles_(make_tiles(film.width(), film.height())),
      tile_locks_(tiles_.size()),
      tile_generation_(tiles_.size()) {}

RenderSession::~RenderSession() = default;

void RenderSession::request_stop(StopReason reason) {
    int expected = int(StopReason::complete);
    stop_reason_.compare_exchange_strong(expected, int(reason));
    stop_.store(true);
}

double RenderSession::elapsed_seconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
}

double RenderSession::eta_seconds() const {
    const double t = elapsed_seconds();
    const uint64_t done = samples_.load();
    double eta =
        done > 0 ? t * double(samples_planned_ - std::min(done, samples_planned_)) / double(done) : -1.0;
    if (scene_.render.time_limit_s) {
        const double left = std::max(0.0, *scene_.render.time_limit_s - t);
        eta = eta < 0 ? left : std::min(eta, left);
    }
    return eta;
}

uint64_t RenderSession::render_tile(size_t tile, const std::vector<uint32_t>* targets,
                                    uint32_t uniform_target) {
    const Camera camera(scene_.camera, film_.width(), film_.height());
    Sampler sampler(scene_.render.seed, scene_.render.sampler);
    const TileRect& r = tiles_[tile];
    uint64_t taken = 0;
    std::lock_guard lock(tile_locks_[tile]);
    if (use_packets(scene_)) {
        taken = render_tile_packets(
            scene_, camera, film_, sampler, r,
            [&](int x, int y, uint32_t& b, uint32_t& e) {
                b = film_.count(x, y);
                e = targets ? (*targets)[size_t(y) * size_t(film_.width()) + size_t(x)] : uniform_target;
            },
            &stop_);
        tile_generation_[tile].fetch_add(1, std::memory_order_release);
        return taken;
    }
    for (int y = r.y0; y < r.y1 && !stop_.load(std::memory_order_relaxed); ++y)
        for (int x = r.x0; x < r.x1 && !stop_.load(std::memory_order_relaxed); ++x) {
            const uint32_t begin = film_.count(x, y);
            const uint32_t end =
                targets ? (*targets)[size_t(y) * size_t(film_.width()) + size_t(x)] : uniform_target;
            if (end <= begin) continue;
            render_pixel(scene_, camera, film_, sampler, x, y, begin, end);
            taken += end - begin;
        }
    tile_generation_[tile].fetch_add(1, std::memory_order_release);
    return taken;
}

void RenderSession::run_pass(const std::vector<uint32_t>* targets, uint32_t uniform_target) {
#pragma omp parallel num_threads(threads_)
    {
#pragma omp for schedule(dynamic, 1) nowait
        for (size_t t = 0; t < tiles_.size(); ++t) {
            if (stop_.load(std::memory_order_relaxed)) continue;
            const uint64_t n = render_tile(t, targets, uniform_target);
            samples_.fetch_add(n, std::memory_order_relaxed);
            progress_->advance(n, n);
        }
        flush_thread_counters();
    }
}

/// One round of adaptive sampling (see adaptive_sample_targets).
bool RenderSession::adaptive_round() {
    std::vector<uint32_t> targets;
    if (!adaptive_sample_targets(film_, *scene_.render.target_error, uint32_t(scene_.render.spp), targets))
        return false;
    pass_target_.store(0);
    run_pass(&targets, 0);
    return true;
}

void RenderSession::render_all() {
    const int spp = scene_.render.spp;
    const bool adaptive = scene_.render.target_error.has_value();
    int done = int(min_sample_count(film_));
    spp_complete_.store(done);
    const int uniform_end = adaptive ? std::min(spp, std::max(done, kAdaptiveMinSpp)) : spp;
    // Progressive passes of doubling size: an early pass gives a full preview,
    // and later passes amortise the per-pass overhead.
    int pass = std::clamp(done, 1, kMaxPassSpp);
    while (done < uniform_end && !stop_.load()) {
        const int end = std::min(uniform_end, done + pass);
        pass_target_.store(end);
        run_pass(nullptr, uint32_t(end));
        if (stop_.load()) break;
        done = end;
        spp_complete_.store(done);
        pass = std::min(pass * 2, kMaxPassSpp);
    }
    if (adaptive && !stop_.load()) {
        while (!stop_.load() && adaptive_round()) spp_complete_.store(int(min_sample_count(film_)));
        if (!stop_.load()) request_stop(StopReason::converged);
    }
}

RenderResult RenderSession::run() {
    const uint64_t pixels = uint64_t(film_.width()) * uint64_t(film_.height());
    uint64_t already = 0;
    for (int y = 0; y < film_.height(); ++y)
        for (int x = 0; x < film_.width(); ++x) already += film_.count(x, y);
    const uint64_t full = pixels * uint64_t(scene_.render.spp);
    samples_planned_ = std::max<uint64_t>(1, full - std::min(full, already));
    progress_ = std::make_unique<Progress>(samples_planned_, "samples", options_.progress);
    start_ = Clock::now();

    std::mutex m;
    std::condition_variable cv;
    bool finished = false;
    std::exception_ptr error;
    std::thread worker([&] {
        try {
            render_all();
        } catch (...) {
            error = std::current_exception();
        }
        std::lock_guard lock(m);
        finished = true;
        cv.notify_all();
    });
    // The calling thread supervises: stop requests, the time limit, on_tick.
    const auto tick = std::chrono::duration<double>(options_.tick_seconds);
    for (;;) {
        {
            std::unique_lock lock(m);
            if (cv.wait_for(lock, tick, [&] { return finished; })) break;
        }
        if (options_.stop && options_.stop->load()) request_stop(StopReason::interrupted);
        if (scene_.render.time_limit_s && elapsed_seconds() >= *scene_.render.time_limit_s)
            request_stop(StopReason::time_limit);
        if (options_.on_tick) options_.on_tick(*this);
    }
    worker.join();
    progress_->finish();
    if (error) std::rethrow_exception(error);

    RenderResult r;
    r.seconds = elapsed_seconds();
    r.samples = samples_.load();
    r.spp_done = int(min_sample_count(film_));
    uint64_t total = 0;
    for (int y = 0; y < film_.height(); ++y)
        for (int x = 0; x < film_.width(); ++x) {
            r.spp_max = std::max(r.spp_max, int(film_.count(x, y)));
            total += film_.count(x, y);
        }
    r.spp_mean = double(total) / double(std::max<uint64_t>(pixels, 1));
    r.nonfinite = film_.nonfinite_samples();
    r.stop = StopReason(stop_reason_.load());
    spp_complete_.store(r.spp_done);
    return r;
}

void RenderSession::visit_changed_tiles(std::vector<uint64_t>& seen, bool wait,
                                        const std::function<void(const TileRect&)>& fn) {
    seen.resize(tiles_.size(), ~uint64_t(0));
    for (size_t t = 0; t < tiles_.size(); ++t) {
        const uint64_t gen = tile_generation_[t].load(std::memory_order_acquire);
        if (gen == seen[t]) continue;
        std::unique_lock lock(tile_locks_[t], std::defer_lock);
        if (wait)
            lock.lock();
        else if (!lock.try_lock())
            continue;
        seen[t] = tile_generation_[t].load(std::memory_order_relaxed);
        fn(tiles_[t]);
    }
}

void RenderSession::snapshot(Film& out) {
    for (size_t t = 0; t < tiles_.size(); ++t) {
        std::lock_guard lock(tile_locks_[t]);
        const TileRect& r = tiles_[t];
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x)
                out.set_pixel_state(x, y, film_.sum(x, y), film_.sum_sq(x, y), film_.count(x, y));
    }
    out.add_nonfinite(film_.nonfinite_samples() - out.nonfinite_samples());
}

RenderResult render_image(const Scene& scene, Film& film, const RenderOptions& options) {
    RenderSession session(scene, film, options);
    return session.run();
}

std::vector<float> relative_error_map(const Film& film) {
    std::vector<float> err(size_t(film.width()) * size_t(film.height()), 0.0f);
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const uint32_t n = film.count(x, y);
            if (n < 2) continue;
            const double mean = luminance_d(film.sum(x, y)) / double(n);
            const double var_of_mean = film.luminance_variance(x, y) / double(n);
            err[size_t(y) * size_t(film.width()) + size_t(x)] =
                float(std::sqrt(var_of_mean / (mean * mean + kRelErrorEpsilon)));
        }
    return err;
}

double estimated_relative_error(const Film& film) {
    const std::vector<float> err = relative_error_map(film);
    double sum = 0;
    for (float e : err) sum += double(e) * double(e);
    return err.empty() ? 0.0 : std::sqrt(sum / double(err.size()));
}

double relative_error_to(const Film& film, const std::vector<float>& reference_rgb) {
    double sum = 0;
    const size_t n = size_t(film.width()) * size_t(film.height());
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const size_t i = size_t(y) * size_t(film.width()) + size_t(x);
            const float* r = &reference_rgb[i * 3];
            const double ref = luminance_d(Vec3d(double(r[0]), double(r[1]), double(r[2])));
            const double d = luminance_d(Vec3d(film.mean(x, y))) - ref;
            sum += d * d / (ref * ref + kRelErrorEpsilon);
        }
    return n ? std::sqrt(sum / double(n)) : 0.0;
}

bool adaptive_sample_targets(const Film& film, double target, uint32_t cap, std::vector<uint32_t>& targets) {
    const int w = film.width(), h = film.height();
    const std::vector<float> err = relative_error_map(film);
    targets.assign(err.size(), 0);
    bool any = false;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Smoothing spreads demand to neighbours whose own estimate is luckily low.
            double e2 = 0;
            int n = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const double e = err[size_t(yy) * size_t(w) + size_t(xx)];
                    e2 += e * e;
                    ++n;
                }
            const double e = std::sqrt(e2 / n);
            const uint32_t count = film.count(x, y);
            uint32_t want = count;
            if (e > target && count < cap) {
                const double needed = std::ceil(double(count) * (e / target) * (e / target)) - double(count);
                const uint32_t more = uint32_t(std::clamp(needed, 4.0, double(std::max(count, 4u))));
                want = std::min(cap, count + more);
                any = true;
            }
            targets[size_t(y) * size_t(w) + size_t(x)] = want;
        }
    return any;
}

uint32_t min_sample_count(const Film& film) {
    uint32_t m = ~0u;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) m = std::min(m, film.count(x, y));
    return film.width() > 0 && film.height() > 0 ? m : 0;
}

}  // namespace sahara
