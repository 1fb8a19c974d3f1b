#pragma once
/// The thread team of a build. Accelerator::build opens one parallel region for all its
/// stages (primitive boxes, binary tree, collapse, leaf storage, the largest-box share and
/// the occlusion order's sample rays), so the workers wait for tasks between
/// stages instead of being woken for each stage's own region (a worker woken late did
/// none of a short stage). Each stage runs its tasks in that team, or in a region of its
/// own when it is called alone (tests, tools).
#include <exception>

#include <omp.h>

namespace sahara::build {

/// Calls fn() on the calling thread with the team's other threads free to take its tasks;
/// every task fn creates has ended when this returns. Inside an active parallel region the
/// caller must be the only thread calling it (the region's master); otherwise a region is
/// opened and fn runs on the main thread (master, not any thread: the stages allocate, and
/// the main thread's malloc arena reuses the pages earlier stages freed). `parallel`
/// false: fn() alone, no region (a build too small to wake the workers for).
template <class Fn>
void with_build_team(const Fn& fn, bool parallel = true) {
    if (!parallel) {
        fn();
        return;
    }
    if (omp_in_parallel()) {
#pragma omp taskgroup
        fn();
        return;
    }
    // An exception may not leave the region: carried out and thrown again.
    std::exception_ptr error;
#pragma omp parallel
#pragma omp master
#pragma omp taskgroup
    {
        try {
            fn();
        } catch (...) {
            error = std::current_exception();
        }
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace sahara::build
