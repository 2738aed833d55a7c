#include "topstoc/core/parallel.hpp"

#include <dirent.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>

namespace topstoc {

namespace {

// Runnable threads on the whole machine at this instant (the kernel's count, caller included);
// -1 when unknown.
int runnable_threads() {
  std::FILE* file = std::fopen("/proc/loadavg", "r");
  if (!file) return -1;
  double one, five, fifteen;
  int running = 0, total = 0;
  const int read = std::fscanf(file, "%lf %lf %lf %d/%d", &one, &five, &fifteen, &running, &total);
  std::fclose(file);
  return read == 5 ? running : -1;
}

// Runnable threads of this process (caller included). Our own OpenMP workers may still be
// spinning after the previous call (libgomp's default wait policy, which Blender's libgomp
// keeps): they would otherwise count as busy cores.
int own_runnable_threads() {
  DIR* tasks = opendir("/proc/self/task");
  if (!tasks) return 1;
  int running = 0;
  char line[512];
  while (const dirent* entry = readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    const std::string path = std::string("/proc/self/task/") + entry->d_name + "/stat";
    std::FILE* file = std::fopen(path.c_str(), "r");
    if (!file) continue;
    const size_t size = std::fread(line, 1, sizeof line - 1, file);
    std::fclose(file);
    line[size] = '\0';
    // "tid (name) S ...": the state follows the last ')' (names may hold spaces and parens).
    const char* close = std::strrchr(line, ')');
    if (close && close[1] == ' ' && close[2] == 'R') ++running;
  }
  closedir(tasks);
  return std::max(running, 1);
}

}  // namespace

int free_cores() {
  // Read before this thread ever changes its own team size: OMP_NUM_THREADS or the core count.
  static const int ceiling = std::max(1, std::min(omp_get_num_procs(), omp_get_max_threads()));
  const int running = runnable_threads();
  if (running < 0) return ceiling;
  if (running <= 1) return ceiling;  // only the caller: no need to look closer
  const int others = running - own_runnable_threads();
  return std::clamp(omp_get_num_procs() - others, 1, ceiling);
}

namespace {
std::atomic<int> running_calls{0};
}  // namespace

RunningCall::RunningCall() { running_calls.fetch_add(1); }
RunningCall::~RunningCall() { running_calls.fetch_sub(1); }

void use_free_cores() {
  // Our own running calls count as busy in free_cores() only while their threads are on a core
  // at this instant; dividing by the calls in flight gives each its share either way.
  omp_set_num_threads(std::max(1, free_cores() / std::max(1, running_calls.load())));
}

}  // namespace topstoc
