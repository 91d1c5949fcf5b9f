// Every GPU test starts with SNAG_REQUIRE_GPU(): without a usable CUDA device (CI has nvcc but
// no GPU) it skips, saying so, instead of passing.
#pragma once

#include <gtest/gtest.h>

#include "snag/cuda/cuda_backend.h"

#define SNAG_REQUIRE_GPU()                                                                  \
  do {                                                                                      \
    if (cuda::cuda_device_count() == 0) GTEST_SKIP() << "no CUDA device: GPU test skipped"; \
  } while (0)
