#include "base/counters.h"

#include <mutex>

namespace sahara {

namespace {
std::mutex g_mutex;
Counters g_totals;
}  // namespace

void flush_thread_counters() {
    std::lock_guard lock(g_mutex);
    g_totals += t_counters;
    t_counters = Counters{};
}

Counters counter_totals() {
    std::lock_guard lock(g_mutex);
    return g_totals;
}

void reset_counters() {
    std::lock_guard lock(g_mutex);
    g_totals = Counters{};
    t_counters = Counters{};
}

}  // namespace sahara
