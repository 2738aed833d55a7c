// When threads pay off: only on long loops, and only on cores that are free.
#pragma once

#include <cstdint>

namespace topstoc {

/// Loops shorter than this run on one thread: starting and joining OpenMP threads costs more
/// than they save below it, and far more when other programs hold the cores (inside Blender a
/// small decimation became a hundred times slower with spinning threads).
constexpr int64_t kParallelMin = 100000;

/// The same for loops whose every step costs about as much as a hundred steps of a plain loop
/// (a sample's link in the partition check, an output vertex's fan): worth two threads much
/// sooner (at 10 % of a million-vertex mesh the partition check's per-sample loop ran on one).
constexpr int64_t kParallelMinCostly = kParallelMin / 50;

/// Cores not busy right now: the online cores (capped by OMP_NUM_THREADS) minus the other
/// runnable threads the kernel counts at this instant (/proc/loadavg), at least 1. An
/// instantaneous count, unlike libgomp's dynamic mode, which follows the 15-minute load
/// average and so throttles a program for work it did itself minutes ago.
int free_cores();

/// Sizes the calling thread's OpenMP teams to its share of free_cores(): engine calls running
/// at the same time (say two preview updates on two threads) split the free cores between them
/// instead of each taking them all. Results never depend on the number of threads.
void use_free_cores();

/// Marks one engine call as running for its lifetime (counted by use_free_cores); each engine
/// entry point holds one, then calls use_free_cores.
class RunningCall {
 public:
  RunningCall();
  ~RunningCall();
  RunningCall(const RunningCall&) = delete;
  RunningCall& operator=(const RunningCall&) = delete;
};

}  // namespace topstoc
