#include <stdexcept>

#include "app/mpi_render.h"

#if SAHARA_HAVE_MPI
#include <condition_variable>
#include <deque>
#include <mutex>

#include "app/mpi_mailbox.h"
#endif

namespace sahara {

#if SAHARA_HAVE_MPI

using namespace mpi_work;

namespace {

/// A worker rank: the main thread talks MPI, the render threads take units
/// from `todo` and put results in `done`.
struct Worker {
    std::mutex m;
    std::condition_variable cv;
    std::deque<TileWork> todo, done;
    bool quit = false;
    std::atomic<bool> stop{false};
    WorkerReport report;

    void render_threads(const Scene& scene, int threads) {
        const Camera camera(scene.camera, scene.render.width, scene.render.height);
#pragma omp parallel num_threads(threads)
        {
            double waited = 0, rendered = 0;
            uint64_t units = 0;
            for (;;) {
                std::unique_lock lock(m);
                const auto t0 = Clock::now();
                cv.wait(lock, [&] { return quit || !todo.empty(); });
                if (!quit) waited += seconds_between(t0, Clock::now());
                if (todo.empty()) break;
                TileWork w = std::move(todo.front());
                todo.pop_front();
                lock.unlock();
                const auto t1 = Clock::now();
                render_work(scene, camera, w, stop);
                w.seconds = seconds_between(t1, Clock::now());
                rendered += w.seconds;
                ++units;
                lock.lock();
                done.push_back(std::move(w));
            }
            flush_thread_counters();
            std::lock_guard lock(m);
            report.wait_seconds += waited;
            report.render_seconds += rendered;
            report.units += units;
        }
    }
};

}  // namespace

void serve_distributed_render(const MpiSession& mpi, const Scene& scene, int threads_arg,
                              const std::atomic<bool>& signal_stop) {
    (void)mpi;
    const int threads = resolve_threads(threads_arg);
    Worker w;
    w.report.threads = uint32_t(threads);
    Mailbox mail;
    mail.send(0, kTagHello, bytes_of(uint32_t(threads)));
    std::thread renderers([&] { w.render_threads(scene, threads); });
    Backoff backoff;
    bool told_leaving = false, stopped = false;
    for (;;) {
        int source = 0, tag = 0;
        std::vector<char> bytes;
        bool progressed = false;
        while (mail.receive(source, tag, bytes)) {
            progressed = true;
            std::lock_guard lock(w.m);
            if (tag == kTagWork)
                w.todo.push_back(decode_work(bytes));
            else if (tag == kTagStop)
                stopped = w.quit = true;
            w.cv.notify_all();
        }
        if (stopped) w.stop.store(true);  // rank 0 stopped the job (or finished it)
        if (signal_stop.load() && !told_leaving) {
            // Cut the tiles in hand short and let rank 0 give the rest to others.
            w.stop.store(true);
            mail.send(0, kTagLeave, {});
            told_leaving = true;
        }
        std::deque<TileWork> finished;
        bool idle;
        {
            std::lock_guard lock(w.m);
            finished.swap(w.done);
            idle = w.quit && w.todo.empty();
        }
        for (const TileWork& t : finished) mail.send(0, kTagResult, encode_result(t));
        if (!finished.empty()) progressed = true;
        if (idle && renderers.joinable()) {
            renderers.join();  // the threads hold no unit once quit and todo is empty
            for (const TileWork& t : w.done) mail.send(0, kTagResult, encode_result(t));
            w.done.clear();
            w.report.counters = counter_totals();
            mail.send(0, kTagDone, bytes_of(w.report));
        }
        const bool sends_done = mail.progress();
        if (!renderers.joinable() && sends_done) break;
        if (progressed)
            backoff.busy();
        else
            backoff.idle(!sends_done);
    }
}

#else  // !SAHARA_HAVE_MPI

void serve_distributed_render(const MpiSession&, const Scene&, int, const std::atomic<bool>&) {
    throw std::logic_error("sahara was built without MPI");
}

#endif

}  // namespace sahara
