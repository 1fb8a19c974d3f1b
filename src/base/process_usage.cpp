#include "base/process_usage.h"

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <fstream>

namespace sahara {

double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

double peak_rss_mib() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

void reset_peak_rss() {
    std::ofstream("/proc/self/clear_refs") << "5";  // 5: reset the peak resident set size
}

double current_rss_mib() {
    std::ifstream statm("/proc/self/statm");
    long long total_pages = 0, resident_pages = 0;
    if (!(statm >> total_pages >> resident_pages)) return 0.0;
    return double(resident_pages) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

}  // namespace sahara
