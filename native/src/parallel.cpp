#include "topstoc/parallel.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdio>

namespace topstoc {

int free_cores() {
  // Read before this thread ever changes its own team size: OMP_NUM_THREADS or the core count.
  static const int ceiling = std::max(1, std::min(omp_get_num_procs(), omp_get_max_threads()));
  std::FILE* file = std::fopen("/proc/loadavg", "r");
  if (!file) return ceiling;
  double one, five, fifteen;
  int running = 0, total = 0;
  const int read = std::fscanf(file, "%lf %lf %lf %d/%d", &one, &five, &fifteen, &running, &total);
  std::fclose(file);
  if (read != 5 || running < 1) return ceiling;
  // `running` includes the calling thread itself.
  return std::clamp(omp_get_num_procs() - (running - 1), 1, ceiling);
}

void use_free_cores() { omp_set_num_threads(free_cores()); }

}  // namespace topstoc
