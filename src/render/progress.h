#pragma once
/// Progress on stderr for long work: percent, elapsed, ETA and throughput,
/// redrawn at most a few times a second on one line. Thread-safe.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace sahara {

class Progress {
   public:
    /// `total` units of work; `unit` names the throughput (e.g. "samples").
    Progress(uint64_t total, std::string unit, bool enabled);
    ~Progress();
    /// Records `n` more units done and `samples` more samples for the rate.
    void advance(uint64_t n, uint64_t samples);
    /// Clears the line (call before printing the final summary).
    void finish();
    double elapsed_seconds() const;

    /// Whether progress should show by default: stderr is a terminal.
    static bool stderr_is_tty();

   private:
    void draw(bool force);

    uint64_t total_;
    std::string unit_;
    bool enabled_;
    std::atomic<uint64_t> done_{0}, samples_{0};
    std::chrono::steady_clock::time_point start_, last_draw_;
    std::mutex draw_mutex_;
    bool finished_ = false;
};

}  // namespace sahara
