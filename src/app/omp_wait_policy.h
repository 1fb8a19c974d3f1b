#pragma once
/// libgomp's idle threads spin (up to a few hundred thousand pause instructions,
/// milliseconds on current cores) before they sleep, and it reads its wait policy
/// only from the environment, once, when the library loads. Spinning burns a core
/// whenever one thread has nothing to do: the serial steps of an acceleration
/// build, and every moment another process holds the working thread's core. So
/// the executable restarts itself with OMP_WAIT_POLICY=passive unless the user
/// chose a policy (OMP_WAIT_POLICY or GOMP_SPINCOUNT set).

namespace sahara {

/// Whether to restart with a passive wait policy, given the environment's
/// OMP_WAIT_POLICY, GOMP_SPINCOUNT and LD_PRELOAD (null when unset). Not under
/// valgrind (its preload library in LD_PRELOAD): a restart would leave the tool.
bool wants_passive_restart(const char* wait_policy, const char* spin_count, const char* ld_preload);

/// Sets OMP_WAIT_POLICY=passive and executes this program again with `argv`, when
/// wants_passive_restart says so; returns (having changed nothing else) otherwise
/// or when the restart fails.
void restart_with_passive_wait(char** argv);

}  // namespace sahara
