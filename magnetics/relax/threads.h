// OpenMP threads on a machine shared with other processes (docs/benchmarks.md
// "Threads and waiting"): how many the CPU backend takes by default, and how they wait.
#pragma once

#include <string>

namespace odemag {

// The CPU backend's thread count for threads = 0: OMP_NUM_THREADS when it is
// set (its first number); otherwise the cores this process may run on
// (sched_getaffinity), at most the CPU quota of its cgroup rounded up (cgroup
// v2 cpu.max "QUOTA PERIOD", or v1 cpu.cfs_quota_us / cpu.cfs_period_us).
int default_thread_count();

// The rule behind it, for the tests: `cores` allowed by the affinity mask,
// `cpu_max` the text of a cgroup v2 cpu.max file ("max 100000": no quota; ""
// when there is none).
int thread_count_within_quota(int cores, const std::string& cpu_max);

// OpenMP threads that sleep at a barrier instead of spinning: with two runs
// on two cores, spinning threads take the cores the other run's threads wait
// for (each run 2.6 to 4.2 times slower, docs/benchmarks.md "Threads and waiting").
// libgomp reads OMP_WAIT_POLICY once, when it is loaded, so a program sets it
// and runs itself again (execv of /proc/self/exe with argv) when the user
// has not set it; it returns when OMP_WAIT_POLICY is already set (or the
// execv failed). Call it first thing in main.
void restart_with_passive_omp_wait(char** argv);

}  // namespace odemag
