// Every CUDA call is checked: a failure throws snag::InternalError (snag::OutOfMemory when memory
// ran out) with the file, the line, the call and CUDA's own message (cli/main.cpp turns it into
// exit status 4). Nothing here exits.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "snag/error.h"

namespace snag::cuda {

/// `bytes` in whole MiB, rounded up ("3 MiB").
inline std::string mib_text(size_t bytes) {
  return std::to_string((bytes + (size_t{1} << 20) - 1) >> 20) + " MiB";
}

/// The current device's free and total memory in words ("F MiB of T MiB free"), or empty
/// when the device cannot say.
inline std::string free_device_memory_text() {
  size_t free = 0, total = 0;
  if (cudaMemGetInfo(&free, &total) != cudaSuccess) {
    cudaGetLastError();
    return {};
  }
  return mib_text(free) + " of " + mib_text(total) + " free";
}

/// A failed call: snag::OutOfMemory when the device ran out of memory (an allocation, or a
/// stream, event or context that needed some), with what was free; else snag::InternalError.
[[noreturn]] inline void throw_cuda_error(cudaError_t status, const char* what, const char* file,
                                          int line) {
  const std::string call = std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                           cudaGetErrorName(status) + ": " + cudaGetErrorString(status);
  if (status == cudaErrorMemoryAllocation) {
    cudaGetLastError();  // not sticky: the device stays usable
    const std::string free = free_device_memory_text();
    throw OutOfMemory("the GPU ran out of memory (" + call + (free.empty() ? "" : "; " + free) +
                      ")");
  }
  throw InternalError(call);
}

/// A device allocation that did not fit: how much was asked for and how much is free, in
/// words a user can act on (a frame with millions of candidate pairs, on a GPU that is small or
/// shared with another job). The command line adds what to do.
[[noreturn]] inline void throw_out_of_device_memory(size_t bytes) {
  const std::string free = free_device_memory_text();
  throw OutOfMemory("the GPU's memory is too small for this frame: a buffer of " +
                    mib_text(bytes) + " did not fit" + (free.empty() ? "" : " (" + free + ")"));
}

/// Page-locked host memory that could not be had (the host's memory, or its limit on locked
/// memory, `ulimit -l`, in a container).
[[noreturn]] inline void throw_out_of_pinned_memory(size_t bytes) {
  throw OutOfMemory("the host could not lock " + mib_text(bytes) +
                    " of memory for transfers to the GPU (cudaMallocHost)");
}

/// Where an allocation was asked for, which says what its running out means to a user.
enum class MemoryKind { device, pinned_host };

/// A failed allocation of `bytes` (`status` is not cudaSuccess): when memory ran out, the
/// OutOfMemory of its kind (throw_out_of_device_memory, throw_out_of_pinned_memory), else
/// throw_cuda_error's.
[[noreturn]] inline void throw_allocation_error(cudaError_t status, MemoryKind kind, size_t bytes,
                                                const char* what, const char* file, int line) {
  if (status == cudaErrorMemoryAllocation) {
    cudaGetLastError();  // not sticky: the device stays usable
    if (kind == MemoryKind::device) throw_out_of_device_memory(bytes);
    throw_out_of_pinned_memory(bytes);
  }
  throw_cuda_error(status, what, file, line);
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
