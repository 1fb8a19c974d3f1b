#pragma once
/// MPI for one `sahara` command. MPI is initialised only when an MPI launcher
/// (mpirun, mpiexec, srun) started the process, so a plain run never touches
/// MPI and does not slow down; builds without MPI get a one-rank stand-in.
#include <string>

namespace sahara {

/// Whether this build can render across MPI ranks (CMake found MPI).
bool mpi_built();

/// Whether the environment says an MPI launcher started this process.
bool launched_by_mpi();

/// The MPI world of this process: initialised on construction when launched by
/// MPI, finalised on destruction (aborting the whole job if an exception is
/// unwinding, so the other ranks do not wait forever).
class MpiSession {
   public:
    MpiSession();
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    /// More than one rank: the render is split across processes.
    bool distributed() const { return size_ > 1; }

    /// Collective: true on every rank iff `ok` on every rank.
    bool all_ok(bool ok) const;
    /// Collective: rank 0's `text`, on every rank.
    std::string broadcast(const std::string& text) const;
    /// Ends the whole job now (a rank cannot go on and the others would wait).
    [[noreturn]] void abort(int code) const;
    /// Skip MPI_Finalize at exit (it waits for ranks that may be gone); the
    /// process then ends with MPI_Abort(code) in the destructor.
    void abort_at_exit(int code) { abort_code_ = code; }

   private:
    int rank_ = 0, size_ = 1;
    bool initialised_ = false;
    int abort_code_ = -1;
};

}  // namespace sahara
