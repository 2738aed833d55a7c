// What the machine offers right now: its usable cores and the threads of other programs that
// want one. The only place that reads the operating system's process tables (/proc on Linux).
#pragma once

namespace topstoc {

/// Cores this process may run on (its affinity mask on Linux, else the hardware's count), >= 1.
int usable_cores();

/// Runnable threads of other programs at this instant (Linux: /proc/loadavg less this process's
/// own running threads); -1 where unknown.
int other_runnable_threads();

}  // namespace topstoc
