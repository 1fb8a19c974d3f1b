#pragma once
/// MPI plumbing shared by rank 0 (mpi_render.cpp) and the other ranks
/// (mpi_worker.cpp): nonblocking messages and polling. MPI builds only.
#if SAHARA_HAVE_MPI
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <list>
#include <thread>
#include <vector>

#include "app/mpi_work.h"

namespace sahara::mpi_work {

using Clock = std::chrono::steady_clock;

inline double seconds_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
}

inline int resolve_threads(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

/// Nonblocking point-to-point messages. Sends are MPI_Isend with the buffer
/// kept alive until complete: two ranks sending each other large (rendezvous)
/// messages with blocking MPI_Send would deadlock.
class Mailbox {
   public:
    void send(int dest, int tag, std::vector<char> bytes) {
        auto& s = sends_.emplace_back();
        s.bytes = std::move(bytes);
        MPI_Isend(s.bytes.data(), int(s.bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &s.request);
        bytes_sent_ += s.bytes.size();
    }
    /// Completes finished sends; true when none is pending.
    bool progress() {
        for (auto it = sends_.begin(); it != sends_.end();) {
            int done = 0;
            MPI_Test(&it->request, &done, MPI_STATUS_IGNORE);
            it = done ? sends_.erase(it) : std::next(it);
        }
        return sends_.empty();
    }
    /// Receives the next message from anyone, if there is one.
    bool receive(int& source, int& tag, std::vector<char>& bytes) {
        int flag = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
        if (!flag) return false;
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        bytes.resize(size_t(count));
        MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        source = status.MPI_SOURCE;
        tag = status.MPI_TAG;
        return true;
    }
    uint64_t bytes_sent() const { return bytes_sent_; }

   private:
    struct Pending {
        MPI_Request request = MPI_REQUEST_NULL;
        std::vector<char> bytes;
    };
    std::list<Pending> sends_;  // a list: buffers must not move while in flight
    uint64_t bytes_sent_ = 0;
};

/// Polling with a growing sleep: MPI's blocking calls spin and would take a
/// core from the render threads; a few hundred microseconds of latency is
/// hidden by the unit each rank holds in reserve.
class Backoff {
   public:
    /// `sending`: messages are still going out; poll soon so MPI can move them on.
    void idle(bool sending) {
        std::this_thread::sleep_for(std::chrono::microseconds(us_));
        us_ = std::min(us_ * 2, sending ? 100 : 2000);
    }
    void busy() { us_ = 50; }

   private:
    int us_ = 50;
};

template <class T>
inline std::vector<char> bytes_of(const T& v) {
    Writer w;
    w.put(v);
    return std::move(w.bytes);
}

}  // namespace sahara::mpi_work
#endif
