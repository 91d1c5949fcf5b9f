// The thread count of an OpenMP loop from a `--threads`-style setting.
#pragma once

#include <omp.h>

namespace snag {

/// `threads` when positive, else OpenMP's default (every core, or OMP_NUM_THREADS).
inline int thread_count(int threads) {
  return threads > 0 ? threads : omp_get_max_threads();
}

}  // namespace snag
