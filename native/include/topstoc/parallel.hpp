// When threads pay off: only on long loops, and only when cores are free.
#pragma once

#include <cstdint>

namespace topstoc {

/// Loops shorter than this run on one thread: starting and joining OpenMP threads costs more
/// than they save below it, and far more when other programs hold the cores (inside Blender, a
/// 500-vertex decimation took 1.3 s with spinning threads and 8 ms without).
constexpr int64_t kParallelMin = 100000;

/// Lets OpenMP use fewer threads while the machine is busy (libgomp then sizes teams by the
/// load average). Called once when the Python module loads. Results never depend on the
/// number of threads.
void adapt_threads_to_load();

}  // namespace topstoc
