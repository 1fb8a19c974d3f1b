#include "app/mpi_render.h"

#include <cstdio>
#include <stdexcept>

#if SAHARA_HAVE_MPI
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>

#include "app/mpi_mailbox.h"
#include "base/log.h"
#include "render/progress.h"
#endif

namespace sahara {

#if SAHARA_HAVE_MPI

using namespace mpi_work;

namespace {

/// Samples per pixel of one unit (one pass over a tile). RenderSession starts
/// with 1-spp passes for a quick preview; here every unit is a full pass, so a
/// 16x16 tile carries 16k samples against ~10 KB of state each way. Pass sizes
/// do not change the image: each pixel takes its samples in index order.
constexpr int kPassSpp = 64;

}  // namespace

// --- rank 0 -----------------------------------------------------------------

/// A unit waiting to be handed out: a tile and its target (uniform, or the
/// current adaptive round's per-pixel targets).
struct Unit {
    uint32_t tile = 0;
    uint32_t uniform_target = 0;
    bool adaptive = false;
};

struct DistributedRender::Impl {
    Impl(const MpiSession& m, const Scene& s, Film& f, DistributedOptions o)
        : mpi(m),
          scene(s),
          film(f),
          options(std::move(o)),
          threads(resolve_threads(options.threads)),
          camera(s.camera, f.width(), f.height()) {
        for (int y0 = 0; y0 < f.height(); y0 += kTileSize)
            for (int x0 = 0; x0 < f.width(); x0 += kTileSize)
                tiles.push_back(
                    {x0, y0, std::min(x0 + kTileSize, f.width()), std::min(y0 + kTileSize, f.height())});
        busy.assign(tiles.size(), 0);
        peers.resize(size_t(mpi.size()));
    }

    struct Peer {
        uint32_t slots = 0;                ///< units it may hold (2 per thread + 1)
        std::map<uint32_t, Unit> holding;  ///< tile -> unit sent and not returned
        bool stop_sent = false, done = false, left = false;
        WorkerReport report;
    };

    // -- scheduler; everything below `m` is guarded by it --
    uint32_t target_of(const Unit& u, int x, int y) const {
        return u.adaptive ? round_targets[size_t(y) * size_t(film.width()) + size_t(x)] : u.uniform_target;
    }
    bool needs_work(const Unit& u) const {
        const TileRect& r = tiles[u.tile];
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x)
                if (film.count(x, y) < target_of(u, x, y)) return true;
        return false;
    }
    /// The first pending unit whose tile is free (units of a tile go out one at
    /// a time, in order); units with nothing left to do are dropped.
    std::optional<Unit> take_locked() {
        if (closed) return std::nullopt;
        for (auto it = pending.begin(); it != pending.end();) {
            if (busy[it->tile]) {
                ++it;
                continue;
            }
            const Unit u = *it;
            it = pending.erase(it);
            if (!needs_work(u)) continue;
            busy[u.tile] = 1;
            ++in_flight;
            return u;
        }
        return std::nullopt;
    }
    TileWork make_work_locked(const Unit& u) const {
        TileWork w;
        w.tile = u.tile;
        w.rect = tiles[u.tile];
        for (int y = w.rect.y0; y < w.rect.y1; ++y)
            for (int x = w.rect.x0; x < w.rect.x1; ++x) {
                w.targets.push_back(target_of(u, x, y));
                w.state.push_back({film.sum(x, y), film.sum_sq(x, y), film.count(x, y), 0});
            }
        return w;
    }
    /// Stores a returned unit; a unit cut short (a stopped rank) goes back in the queue.
    void apply_locked(const TileWork& w, const Unit& u) {
        const TileRect& r = tiles[u.tile];
        const int tw = r.x1 - r.x0;
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                const PixelState& p = w.state[size_t(y - r.y0) * size_t(tw) + size_t(x - r.x0)];
                film.set_pixel_state(x, y, p.sum, p.sum_sq, p.count);
            }
        film.add_nonfinite(w.nonfinite);
        samples.fetch_add(w.samples, std::memory_order_relaxed);
        progress->advance(w.samples, w.samples);
        release_locked(u);
    }
    void release_locked(const Unit& u) {
        busy[u.tile] = 0;
        --in_flight;
        if (!closed && needs_work(u)) pending.push_front(u);
    }
    void close() {
        {
            std::lock_guard lock(m);
            closed = true;
        }
        cv.notify_all();
    }

    void enqueue_uniform_passes();
    bool enqueue_adaptive_round();
    void local_threads();
    void top_up(int rank);
    void handle(int source, int tag, const std::vector<char>& bytes);
    void begin_stop(StopReason reason);
    bool coordinate_step(Backoff& backoff);
    RenderResult result() const;

    const MpiSession& mpi;
    const Scene& scene;
    Film& film;
    DistributedOptions options;
    int threads;
    Camera camera;
    std::vector<TileRect> tiles;

    std::mutex m;
    std::condition_variable cv;
    std::list<Unit> pending;
    std::vector<char> busy;
    size_t in_flight = 0;
    bool closed = false;
    std::vector<uint32_t> round_targets;  ///< the current adaptive round's per-pixel targets

    std::atomic<bool> local_stop{false};
    std::atomic<uint64_t> samples{0};
    std::unique_ptr<Progress> progress;
    Clock::time_point start, stop_time;
    bool stopping = false, adaptive_phase = false;
    StopReason reason = StopReason::complete;
    std::vector<Peer> peers;
    Mailbox mail;
    int lost = 0;
    WorkerReport local_report;       ///< rank 0's own render threads
    double coordinator_seconds = 0;  ///< rank 0's time handling messages (decode, apply, encode)
    uint64_t messages = 0;
};

void DistributedRender::Impl::enqueue_uniform_passes() {
    const int spp = scene.render.spp;
    int done = int(min_sample_count(film));
    const int uniform_end = scene.render.target_error ? std::min(spp, std::max(done, kAdaptiveMinSpp)) : spp;
    std::lock_guard lock(m);
    while (done < uniform_end) {
        const int end = std::min(uniform_end, done + kPassSpp);
        for (uint32_t t = 0; t < tiles.size(); ++t) pending.push_back({t, uint32_t(end), false});
        done = end;
    }
}

/// At a barrier (no unit pending or in flight): the next adaptive round, as
/// RenderSession::adaptive_round computes it from the whole film.
bool DistributedRender::Impl::enqueue_adaptive_round() {
    std::lock_guard lock(m);
    if (!adaptive_sample_targets(film, *scene.render.target_error, uint32_t(scene.render.spp), round_targets))
        return false;
    for (uint32_t t = 0; t < tiles.size(); ++t) pending.push_back({t, 0, true});
    return true;
}

/// Rank 0's own render threads take units from the same queue as the other ranks.
void DistributedRender::Impl::local_threads() {
#pragma omp parallel num_threads(threads)
    {
        double waited = 0, rendered = 0;
        uint64_t units = 0;
        for (;;) {
            std::unique_lock lock(m);
            std::optional<Unit> u;
            const auto t0 = Clock::now();
            while (!closed && !(u = take_locked())) cv.wait(lock);
            if (!u) break;
            waited += seconds_between(t0, Clock::now());
            TileWork w = make_work_locked(*u);
            lock.unlock();
            const auto t1 = Clock::now();
            render_work(scene, camera, w, local_stop);
            rendered += seconds_between(t1, Clock::now());
            ++units;
            lock.lock();
            apply_locked(w, *u);
            lock.unlock();
            cv.notify_all();
        }
        flush_thread_counters();
        std::lock_guard lock(m);
        local_report.units += units;
        local_report.render_seconds += rendered;
        local_report.wait_seconds += waited;
    }
}

void DistributedRender::Impl::top_up(int rank) {
    Peer& p = peers[size_t(rank)];
    while (!p.left && p.holding.size() < p.slots) {
        std::unique_lock lock(m);
        const std::optional<Unit> u = take_locked();
        if (!u) return;
        TileWork w = make_work_locked(*u);
        lock.unlock();
        p.holding[u->tile] = *u;
        mail.send(rank, kTagWork, encode_work(w));
    }
}

void DistributedRender::Impl::handle(int source, int tag, const std::vector<char>& bytes) {
    Peer& p = peers[size_t(source)];
    if (tag == kTagHello) {
        // Two units per thread plus one: the spare hides the round trip to rank 0,
        // even when rank 0's coordinating thread waits for a core.
        p.slots = 2 * Reader(bytes).get<uint32_t>() + 1;
    } else if (tag == kTagResult) {
        const uint32_t tile = peek_tile(bytes);
        const auto it = p.holding.find(tile);
        if (it == p.holding.end()) throw std::runtime_error("sahara: rank 0 got a tile it never sent");
        TileWork w;
        w.rect = tiles.at(tile);
        decode_result(bytes, w);
        const Unit u = it->second;
        p.holding.erase(it);
        {
            std::lock_guard lock(m);
            apply_locked(w, u);
        }
        cv.notify_all();
    } else if (tag == kTagLeave) {
        if (!stopping && !(options.stop && options.stop->load()))
            log_warning("rank " + std::to_string(source) +
                        " was stopped; the other ranks take over its tiles");
        p.left = true;
        if (!p.stop_sent) mail.send(source, kTagStop, {});
        p.stop_sent = true;
    } else if (tag == kTagDone) {
        p.report = Reader(bytes).get<WorkerReport>();
        p.done = true;
        {
            std::lock_guard lock(m);
            for (const auto& [tile, u] : p.holding) release_locked(u);
        }
        p.holding.clear();
        cv.notify_all();
    }
}

void DistributedRender::Impl::begin_stop(StopReason why) {
    if (stopping) return;
    stopping = true;
    reason = why;
    stop_time = Clock::now();
    if (why != StopReason::complete && why != StopReason::converged) local_stop.store(true);
    close();
    for (int r = 1; r < mpi.size(); ++r)
        if (!peers[size_t(r)].stop_sent) {
            mail.send(r, kTagStop, {});
            peers[size_t(r)].stop_sent = true;
        }
}

/// One round of the coordinating loop; false when the render is over.
bool DistributedRender::Impl::coordinate_step(Backoff& backoff) {
    if (!stopping) {
        if (options.stop && options.stop->load())
            begin_stop(StopReason::interrupted);
        else if (scene.render.time_limit_s &&
                 seconds_between(start, Clock::now()) >= *scene.render.time_limit_s)
            begin_stop(StopReason::time_limit);
    }
    int source = 0, tag = 0;
    std::vector<char> bytes;
    bool progressed = false;
    const auto t0 = Clock::now();
    while (mail.receive(source, tag, bytes)) {
        handle(source, tag, bytes);
        progressed = true;
        ++messages;
    }
    const bool sends_done = mail.progress();
    if (!stopping) {
        bool barrier;
        {
            std::lock_guard lock(m);
            barrier = pending.empty() && in_flight == 0;
        }
        if (barrier) {
            adaptive_phase = adaptive_phase || scene.render.target_error.has_value();
            if (!adaptive_phase || !enqueue_adaptive_round())
                begin_stop(adaptive_phase ? StopReason::converged : StopReason::complete);
            cv.notify_all();
        }
        for (int r = 1; r < mpi.size(); ++r) top_up(r);
    }
    if (progressed) coordinator_seconds += seconds_between(t0, Clock::now());
    if (stopping) {
        bool all_done = true;
        for (int r = 1; r < mpi.size(); ++r) all_done = all_done && peers[size_t(r)].done;
        if (all_done && sends_done) return false;
        const double grace =
            reason == StopReason::interrupted ? options.signal_grace_seconds : options.stop_grace_seconds;
        if (seconds_between(stop_time, Clock::now()) > grace) {
            for (int r = 1; r < mpi.size(); ++r)
                if (!peers[size_t(r)].done) {
                    log_warning("rank " + std::to_string(r) + " did not answer; its " +
                                std::to_string(peers[size_t(r)].holding.size()) +
                                " tiles in flight keep their last state");
                    ++lost;
                }
            return false;
        }
    }
    if (progressed)
        backoff.busy();
    else
        backoff.idle(!sends_done);
    return true;
}

RenderResult DistributedRender::Impl::result() const {
    RenderResult r;
    r.seconds = seconds_between(start, Clock::now());
    r.samples = samples.load();
    r.spp_done = int(min_sample_count(film));
    uint64_t total = 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            r.spp_max = std::max(r.spp_max, int(film.count(x, y)));
            total += film.count(x, y);
        }
    r.spp_mean =
        double(total) / double(std::max<uint64_t>(uint64_t(film.width()) * uint64_t(film.height()), 1));
    r.nonfinite = film.nonfinite_samples();
    r.stop = reason;
    return r;
}

DistributedRender::DistributedRender(const MpiSession& mpi, const Scene& scene, Film& film,
                                     DistributedOptions options)
    : impl_(std::make_unique<Impl>(mpi, scene, film, std::move(options))) {}

DistributedRender::~DistributedRender() = default;

RenderResult DistributedRender::run() {
    Impl& s = *impl_;
    uint64_t already = 0;
    for (int y = 0; y < s.film.height(); ++y)
        for (int x = 0; x < s.film.width(); ++x) already += s.film.count(x, y);
    const uint64_t full = uint64_t(s.film.width()) * uint64_t(s.film.height()) * uint64_t(s.scene.render.spp);
    s.progress = std::make_unique<Progress>(std::max<uint64_t>(1, full - std::min(full, already)), "samples",
                                            s.options.progress);
    s.start = Clock::now();
    s.enqueue_uniform_passes();
    std::thread workers([&s] { s.local_threads(); });
    Backoff backoff;
    auto next_tick = Clock::now();
    try {
        while (s.coordinate_step(backoff)) {
            if (s.options.on_tick && Clock::now() >= next_tick) {
                s.options.on_tick(*this);
                next_tick = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(s.options.tick_seconds));
            }
        }
    } catch (...) {
        s.local_stop.store(true);
        s.close();
        workers.join();
        throw;
    }
    workers.join();
    s.progress->finish();
    for (int r = 1; r < s.mpi.size(); ++r) {
        t_counters += s.peers[size_t(r)].report.counters;
        flush_thread_counters();
    }
    return s.result();
}

void DistributedRender::snapshot(Film& out) {
    std::lock_guard lock(impl_->m);
    const Film& f = impl_->film;
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x)
            out.set_pixel_state(x, y, f.sum(x, y), f.sum_sq(x, y), f.count(x, y));
    out.add_nonfinite(f.nonfinite_samples() - out.nonfinite_samples());
}

double DistributedRender::elapsed_seconds() const { return seconds_between(impl_->start, Clock::now()); }

int DistributedRender::lost_ranks() const { return impl_->lost; }

std::string DistributedRender::rank_report() const {
    const Impl& s = *impl_;
    std::string out;
    char line[256];
    const auto add = [&](int rank, const WorkerReport& r, int threads) {
        const double per_unit = r.units ? 1e3 / double(r.units) : 0.0;
        std::snprintf(
            line, sizeof line,
            "rank %d: %d threads, %llu units, render %.3f s (%.2f ms/unit), waiting for units %.3f s "
            "(%.3f ms/unit)\n",
            rank, threads, static_cast<unsigned long long>(r.units), r.render_seconds,
            r.render_seconds * per_unit, r.wait_seconds, r.wait_seconds * per_unit);
        out += line;
    };
    add(0, s.local_report, s.threads);
    for (int r = 1; r < s.mpi.size(); ++r)
        add(r, s.peers[size_t(r)].report, int(s.peers[size_t(r)].report.threads));
    std::snprintf(line, sizeof line,
                  "rank 0 coordinator: %llu messages, %.3f s handling them, %.2f MB sent\n",
                  static_cast<unsigned long long>(s.messages), s.coordinator_seconds,
                  double(s.mail.bytes_sent()) / 1e6);
    out += line;
    return out;
}

#else  // !SAHARA_HAVE_MPI

struct DistributedRender::Impl {};

DistributedRender::DistributedRender(const MpiSession&, const Scene&, Film&, DistributedOptions) {
    throw std::logic_error("sahara was built without MPI");
}
DistributedRender::~DistributedRender() = default;
RenderResult DistributedRender::run() { return {}; }
void DistributedRender::snapshot(Film&) {}
double DistributedRender::elapsed_seconds() const { return 0; }
int DistributedRender::lost_ranks() const { return 0; }
std::string DistributedRender::rank_report() const { return {}; }

#endif

}  // namespace sahara
