#include "base/pending_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstring>

namespace sahara {

namespace {

// A fixed buffer, not a std::string: the signal handler may only read plain memory.
char g_path[4096];
std::atomic<bool> g_active{false};

}  // namespace

PendingFile::PendingFile(const std::string& path) {
    const size_t n = std::min(path.size(), sizeof(g_path) - 1);
    std::memcpy(g_path, path.data(), n);
    g_path[n] = '\0';
    g_active.store(true);
}

PendingFile::~PendingFile() { g_active.store(false); }

void remove_pending_file() noexcept {
    if (g_active.load()) ::unlink(g_path);
}

}  // namespace sahara
