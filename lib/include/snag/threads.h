// The thread count of an OpenMP loop from a `--threads`-style setting.
#pragma once

#include <omp.h>

#include <cstdint>

namespace snag {

/// `threads` when positive, else OpenMP's default (every core, or OMP_NUM_THREADS).
inline int thread_count(int threads) {
  return threads > 0 ? threads : omp_get_max_threads();
}

/// body(i) for every i in [0, n): split statically over `threads` OpenMP threads when n is above
/// `serial_up_to`, else in a plain loop on the calling thread. A parallel region costs about a
/// microsecond even when an `if` clause leaves it one thread, and the loops that run every frame
/// (on small meshes, or once per tree level) add that up: a 2,244-triangle refit took 36 us
/// with a region per level, 21 without (lib/NOTES.md). `body` is a lambda, inlined in both loops.
template <class Body>
void for_each_index(int threads, int64_t n, int64_t serial_up_to, Body&& body) {
  if (n <= serial_up_to) {
    for (int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int64_t i = 0; i < n; ++i) body(i);
}

}  // namespace snag
