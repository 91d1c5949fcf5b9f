// Every CUDA call is checked: a failure throws snag::InternalError with the file, the line, the
// call and CUDA's own message (cli/main.cpp turns it into exit status 4). Nothing here exits.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "snag/error.h"

namespace snag::cuda {

[[noreturn]] inline void throw_cuda_error(cudaError_t status, const char* what, const char* file,
                                          int line) {
  throw InternalError(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                      cudaGetErrorName(status) + ": " + cudaGetErrorString(status));
}

/// A device allocation that did not fit: how much was asked for and how much is free, in
/// words a user can act on (a frame with millions of candidate pairs, on a GPU that is small or
/// shared with another job). The command line adds what to do.
[[noreturn]] inline void throw_out_of_device_memory(size_t bytes) {
  size_t free = 0, total = 0;
  if (cudaMemGetInfo(&free, &total) != cudaSuccess) cudaGetLastError();
  const auto mib = [](size_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
  std::string message = "the GPU's memory is too small for this frame: a buffer of ";
  message += mib(bytes);
  message += " did not fit (";
  message += mib(free);
  message += " of ";
  message += mib(total);
  message += " free)";
  throw OutOfDeviceMemory(message);
}

}  // namespace snag::cuda

/// Throws snag::InternalError when `expr` (a CUDA runtime call) does not return cudaSuccess.
#define SNAG_CUDA_CHECK(expr)                                                       \
  do {                                                                              \
    const cudaError_t snag_cuda_status_ = (expr);                                   \
    if (snag_cuda_status_ != cudaSuccess)                                           \
      ::snag::cuda::throw_cuda_error(snag_cuda_status_, #expr, __FILE__, __LINE__); \
  } while (0)

/// After every kernel launch: a bad configuration shows at once, a fault at the next sync.
#define SNAG_CUDA_CHECK_LAUNCH() SNAG_CUDA_CHECK(cudaGetLastError())
