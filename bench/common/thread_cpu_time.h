#pragma once
// CPU time of the calling thread, for the benchmark programs: less disturbed than wall time by
// the other processes of a shared machine (both sides of a comparison run single-threaded).
#include <time.h>

namespace reconar::bench {

inline double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace reconar::bench
