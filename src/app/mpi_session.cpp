#include "app/mpi_session.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <unistd.h>

#include "base/log.h"

#if SAHARA_HAVE_MPI
#include <mpi.h>
#endif

namespace sahara {

namespace {

/// The variables launchers set for each process they start: Open MPI's mpirun,
/// PMI-2 (MPICH/Hydra, Intel MPI, `srun --mpi=pmi2`) and PMIx (`srun --mpi=pmix`, prterun).
const char* const kLauncherVariables[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"};

}  // namespace

bool launched_by_mpi() {
    for (const char* v : kLauncherVariables)
        if (std::getenv(v)) return true;
    return false;
}

#if SAHARA_HAVE_MPI

bool mpi_built() { return true; }

MpiSession::MpiSession() {
    if (!launched_by_mpi()) return;
    // Only the thread that initialised MPI calls it (FUNNELED): the render
    // threads never do, they hand tiles to that thread through queues.
    // A work unit is ~11 KB. Above Open MPI's shared-memory eager limit (4 KB)
    // a message waits for a rendezvous that completes only when the sender
    // calls MPI again, i.e. after its polling sleep: units would stall there.
    // (TCP's eager limit is 64 KB already.) A user's own setting wins.
    ::setenv("OMPI_MCA_btl_vader_eager_limit", "32768", 0);
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    initialised_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    if (const char* dir = std::getenv("SAHARA_MPI_PID_DIR")) {
        // Debugging and tests: which process is which rank (to stop one on purpose).
        const std::string file = std::string(dir) + "/rank-" + std::to_string(rank_) + ".pid";
        if (FILE* f = std::fopen(file.c_str(), "w")) {
            std::fprintf(f, "%d\n", int(::getpid()));
            std::fclose(f);
        }
    }
    const char* tasks = std::getenv("SLURM_NTASKS");
    if (size_ == 1 && tasks && std::atoi(tasks) > 1)
        log_warning(
            "Slurm started " + std::string(tasks) +
            " tasks but MPI sees only this one: every task renders the whole image (use srun --mpi=pmix)");
}

MpiSession::~MpiSession() {
    if (!initialised_) return;
    if (std::uncaught_exceptions() > 0) MPI_Abort(MPI_COMM_WORLD, 1);
    if (abort_code_ >= 0) MPI_Abort(MPI_COMM_WORLD, abort_code_);
    MPI_Finalize();
}

bool MpiSession::all_ok(bool ok) const {
    if (!initialised_) return ok;
    int mine = ok ? 1 : 0, all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all == 1;
}

std::string MpiSession::broadcast(const std::string& text) const {
    if (!initialised_) return text;
    unsigned long long n = text.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    std::string out = rank_ == 0 ? text : std::string(n, '\0');
    MPI_Bcast(out.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD);
    return out;
}

void MpiSession::abort(int code) const {
    std::fflush(stderr);
    if (initialised_) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

#else  // !SAHARA_HAVE_MPI

bool mpi_built() { return false; }

MpiSession::MpiSession() {
    if (launched_by_mpi())
        log_warning(
            "started by an MPI launcher, but this sahara was built without MPI: every rank renders alone");
}

MpiSession::~MpiSession() = default;

bool MpiSession::all_ok(bool ok) const { return ok; }

std::string MpiSession::broadcast(const std::string& text) const { return text; }

void MpiSession::abort(int code) const {
    std::fflush(stderr);
    std::exit(code);
}

#endif

}  // namespace sahara
