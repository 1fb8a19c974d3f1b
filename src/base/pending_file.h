#pragma once
/// The one file being written right now (a temporary before its rename), kept
/// where a signal handler can remove it: an interrupted write must not leave a
/// partial file behind.
#include <string>

namespace sahara {

/// Registers `path` as the file in progress for the lifetime of this object.
class PendingFile {
   public:
    explicit PendingFile(const std::string& path);
    ~PendingFile();
    PendingFile(const PendingFile&) = delete;
    PendingFile& operator=(const PendingFile&) = delete;
};

/// Unlinks the registered file, if any. Async-signal-safe.
void remove_pending_file() noexcept;

}  // namespace sahara
