// CPU time, for benchmarks' accounting of where a run's cores went (POSIX clocks).
#pragma once

#include <sys/resource.h>
#include <time.h>

namespace snag {

/// CPU seconds the whole process has used so far: every thread's user and system time, those
/// of threads already joined included. Spinning counts as use.
inline double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

/// CPU seconds the calling thread has used so far.
inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

}  // namespace snag
