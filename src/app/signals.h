#pragma once
/// SIGINT/SIGTERM during a render: the first asks the render to stop (it then
/// writes what is done and exits 130); the second exits at once, removing a
/// half-written temporary file, without writing anything.
#include <atomic>

namespace sahara {

/// Exit code after an interrupted render (128 + SIGINT, the shell convention).
inline constexpr int kExitInterrupted = 130;

/// Installs the handlers (idempotent). Returns the flag the first signal sets.
const std::atomic<bool>& install_stop_signals();
/// Whether a stop signal has arrived.
bool stop_requested();
/// Restores the default handlers.
void uninstall_stop_signals();

}  // namespace sahara
