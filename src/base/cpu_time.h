// CPU time of the whole process (all threads, user and system). Per-phase CPU seconds stay meaningful on
// a machine shared with other work, where wall time measures the neighbours too.
#pragma once

#include <ctime>

namespace pointrast {

inline double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

} // namespace pointrast
