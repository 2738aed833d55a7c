#include "core/machine_load.hpp"

#include <algorithm>
#include <thread>

#if defined(__linux__)
#include <dirent.h>
#include <sched.h>

#include <cstdio>
#include <cstring>
#include <string>
#endif

namespace topstoc {

#if defined(__linux__)

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

// Runnable threads of this process (caller included). Our own workers may still be spinning
// after the previous call: they would otherwise count as busy cores.
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

int usable_cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, int(std::thread::hardware_concurrency()));
}

int other_runnable_threads() {
  const int running = runnable_threads();
  if (running < 0) return -1;
  if (running <= 1) return 0;  // only the caller: no need to look closer
  return std::max(0, running - own_runnable_threads());
}

#else

int usable_cores() { return std::max(1, int(std::thread::hardware_concurrency())); }

int other_runnable_threads() { return -1; }

#endif

}  // namespace topstoc
