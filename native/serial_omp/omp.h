// The OpenMP runtime calls the engine makes, for builds without OpenMP (-DTOPSTOC_OPENMP=OFF,
// e.g. zig, which has no OpenMP runtime): one thread, as the OpenMP specification's own stub
// routines answer. The `#pragma omp` lines are then ignored and every loop runs serially.
#pragma once

#include <algorithm>
#include <thread>

inline int omp_get_thread_num() { return 0; }
inline int omp_get_num_threads() { return 1; }
inline int omp_get_max_threads() { return 1; }
inline int omp_get_num_procs() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }
inline void omp_set_num_threads(int) {}
