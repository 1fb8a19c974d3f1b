#include "render/progress.h"

#include <unistd.h>

#include <cstdio>

namespace sahara {

using Clock = std::chrono::steady_clock;

Progress::Progress(uint64_t total, std::string unit, bool enabled)
    : total_(total ? total : 1),
      unit_(std::move(unit)),
      enabled_(enabled),
      start_(Clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { finish(); }

bool Progress::stderr_is_tty() { return ::isatty(STDERR_FILENO) != 0; }

double Progress::elapsed_seconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
}

void Progress::advance(uint64_t n, uint64_t samples) {
    done_.fetch_add(n, std::memory_order_relaxed);
    samples_.fetch_add(samples, std::memory_order_relaxed);
    if (enabled_) draw(false);
}

void Progress::draw(bool force) {
    std::unique_lock lock(draw_mutex_, std::try_to_lock);
    if (!lock.owns_lock() || finished_) return;
    const auto now = Clock::now();
    if (!force && now - last_draw_ < std::chrono::milliseconds(250)) return;
    last_draw_ = now;
    const double t = std::chrono::duration<double>(now - start_).count();
    const double frac = double(done_.load()) / double(total_);
    const double eta = frac > 0 ? t * (1.0 - frac) / frac : 0.0;
    const double rate = t > 0 ? double(samples_.load()) / t / 1e6 : 0.0;
    std::fprintf(stderr, "\r  %5.1f%%  elapsed %6.1fs  ETA %6.1fs  %7.2f M%s/s ", 100.0 * frac, t, eta, rate,
                 unit_.c_str());
    std::fflush(stderr);
}

void Progress::finish() {
    std::lock_guard lock(draw_mutex_);
    if (enabled_ && !finished_) {
        std::fprintf(stderr, "\r%72s\r", "");
        std::fflush(stderr);
    }
    finished_ = true;
}

}  // namespace sahara
