#pragma once
/// One image rendered across MPI ranks. Rank 0 holds the film and hands out
/// work units — (tile, per-pixel sample target) — dynamically: every rank,
/// rank 0's own render threads included, gets a new unit as soon as it returns
/// one, so a slow rank never holds the others back. A unit carries its tile's
/// exact accumulator state and comes back with the new state, so each pixel's
/// samples are taken by one rank at a time, in index order, with the same
/// (seed, pixel, sample) streams as one process: the film is bit-identical to
/// a single-process render (same passes, same adaptive rounds).
#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "app/mpi_session.h"
#include "render/film.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace sahara {

class DistributedRender;

struct DistributedOptions {
    int threads = 0;        ///< render threads on rank 0 (0 = all)
    bool progress = false;  ///< progress of the whole job on rank 0's stderr
    /// Signal flag; polled by the coordinating thread.
    const std::atomic<bool>* stop = nullptr;
    /// Called on rank 0's coordinating thread about every tick_seconds (checkpoints).
    std::function<void(DistributedRender&)> on_tick = nullptr;
    double tick_seconds = 0.1;
    /// After the end or a time limit, how long rank 0 waits for the other ranks' tiles in flight.
    double stop_grace_seconds = 10;
    /// The same after a signal: under mpirun it usually means the job is being
    /// killed (Ctrl-C, or a rank died), and mpirun sends SIGKILL one second
    /// after SIGTERM (odls_base_sigkill_timeout), so rank 0 writes soon.
    double signal_grace_seconds = 0.3;
};

/// Rank 0's side of a distributed render. The other ranks run serve_distributed_render.
class DistributedRender {
   public:
    DistributedRender(const MpiSession& mpi, const Scene& scene, Film& film, DistributedOptions options);
    ~DistributedRender();

    /// Renders like RenderSession::run (spp, target error, time limit, stop),
    /// with every rank; the film may already hold samples (resume).
    RenderResult run();
    /// A consistent copy of the film (tiles in flight keep their last returned state).
    void snapshot(Film& out);
    double elapsed_seconds() const;
    /// Ranks that did not answer after the stop (their tiles keep their last state).
    int lost_ranks() const;
    /// Per-rank work and communication figures of the finished render, one line per rank.
    std::string rank_report() const;

   private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Ranks > 0: renders the units rank 0 sends, with `threads` threads (0 = all),
/// until rank 0 says stop, or this rank's `stop` flag is raised (it then
/// returns its partial tiles and leaves the job; rank 0 re-issues the rest).
void serve_distributed_render(const MpiSession& mpi, const Scene& scene, int threads,
                              const std::atomic<bool>& stop);

}  // namespace sahara
