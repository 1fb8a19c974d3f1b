#include "app/omp_wait_policy.h"

#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace sahara {

bool wants_passive_restart(const char* wait_policy, const char* spin_count, const char* ld_preload) {
    if (wait_policy || spin_count) return false;
    return !(ld_preload && std::strstr(ld_preload, "vgpreload"));
}

void restart_with_passive_wait(char** argv) {
    if (!wants_passive_restart(std::getenv("OMP_WAIT_POLICY"), std::getenv("GOMP_SPINCOUNT"),
                               std::getenv("LD_PRELOAD")))
        return;
    // Set before the exec, so a restarted process (which sees it) never restarts again.
    if (::setenv("OMP_WAIT_POLICY", "passive", 0) != 0) return;
    // The resolved path, not /proc/self/exe: the process would be named "exe" in ps and top.
    char path[4096];
    const ssize_t len = ::readlink("/proc/self/exe", path, sizeof(path) - 1);
    if (len <= 0) return;
    path[len] = '\0';
    ::execv(path, argv);
    // The exec failed: run on under the policy libgomp already read.
}

}  // namespace sahara
