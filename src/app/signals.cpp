#include "app/signals.h"

#include <unistd.h>

#include <csignal>

#include "base/pending_file.h"

namespace sahara {

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the handler needs a lock-free flag");

extern "C" void on_stop_signal(int) {
    if (g_stop.exchange(true)) {
        // Second signal: leave now. Only async-signal-safe calls here.
        remove_pending_file();
        ::_exit(kExitInterrupted);
    }
    static const char msg[] =
        "\nsahara: stopping after the samples in flight (again to quit without saving)\n";
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg, sizeof(msg) - 1);
}

void set_handler(int sig, void (*handler)(int)) {
    struct sigaction sa {};
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(sig, &sa, nullptr);
}

}  // namespace

const std::atomic<bool>& install_stop_signals() {
    set_handler(SIGINT, on_stop_signal);
    set_handler(SIGTERM, on_stop_signal);
    return g_stop;
}

bool stop_requested() { return g_stop.load(); }

void uninstall_stop_signals() {
    set_handler(SIGINT, SIG_DFL);
    set_handler(SIGTERM, SIG_DFL);
}

}  // namespace sahara
