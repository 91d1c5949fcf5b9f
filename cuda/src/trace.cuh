// Stream tracing, for a profiling build (cmake -DSNAG_CUDA_TRACE=ON; off by default, and then
// nothing of this is compiled into any kernel). Every kernel that starts with
// wait_for_previous_kernel() (every kernel of a frame, chained or not) records there, on the
// device's global clock (%globaltimer, nanoseconds), when its first block began (before the wait:
// under programmatic dependent launch a kernel's blocks are scheduled while the kernel ahead of it
// runs) and when its first and its last block got past the wait, keyed by the launch's grid
// id. A record's first pass is about where the kernel ahead of it on its stream ended: a
// frame's kernels as the streams ran them, launch gaps and the overlap of neighbours included,
// which ncu, timing each kernel alone, does not show (cuda/NOTES.md, "The 36K frame in the
// stream").
#pragma once

#include <cuda_runtime.h>

#include "cuda_check.cuh"

namespace snag::cuda {

/// One launch, as its blocks recorded it (times in nanoseconds of the device's clock).
struct TraceRecord {
  unsigned long long grid;          ///< the launch's grid id (0: slot unused)
  unsigned long long began;         ///< the earliest block's start, before the wait
  unsigned long long passed_first;  ///< the earliest block past the wait
  unsigned long long passed_last;   ///< the latest block past the wait
  unsigned long long threads;       ///< the grid's threads
};

/// Records kept at once, a slot per grid id modulo this: far more than the launches of a frame.
inline constexpr int kTraceSlots = 256;

/// The current device's records (kTraceSlots of them), made, reset and pointed at by every
/// translation unit's kernels on first use and kept for the process's life, so that nothing a
/// kernel writes outlives them; null in a build without SNAG_CUDA_TRACE. One buffer per device:
/// every backend on it records there, so one backend is traced at a time.
TraceRecord* stream_trace_buffer();

/// Sets `records` back to unused and waits until the device has them (a no-op in a build
/// without SNAG_CUDA_TRACE).
void reset_stream_trace(TraceRecord* records);

#if defined(SNAG_CUDA_TRACE)
/// Without relocatable device code a __device__ variable is one per translation unit, so each
/// unit that defines kernels has its own pointer and a function of its own to set it
/// (stream_trace_buffer calls them all).
static __device__ TraceRecord* g_trace_records = nullptr;

__device__ __forceinline__ unsigned long long trace_clock() {
  unsigned long long ns;
  asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(ns));
  return ns;
}

/// A block's record of its launch: thread 0 only, `began` read before the wait.
__device__ __forceinline__ void trace_launch(unsigned long long began) {
  TraceRecord* const records = g_trace_records;
  if (records == nullptr || (threadIdx.x | threadIdx.y | threadIdx.z) != 0) return;
  const unsigned long long passed = trace_clock();
  unsigned long long grid;
  asm volatile("mov.u64 %0, %%gridid;" : "=l"(grid));
  TraceRecord& r = records[grid % kTraceSlots];
  // A slot another launch holds (grid ids need not be consecutive): this launch is left out
  // rather than merged into that one's record.
  const unsigned long long holder = atomicCAS(&r.grid, 0ull, grid);
  if (holder != 0 && holder != grid) return;
  atomicMin(&r.began, began);
  atomicMin(&r.passed_first, passed);
  atomicMax(&r.passed_last, passed);
  r.threads = static_cast<unsigned long long>(gridDim.x) * gridDim.y * gridDim.z * blockDim.x *
              blockDim.y * blockDim.z;
}

/// Defines the unit's setter, named after it.
#define SNAG_CUDA_TRACE_UNIT(unit)                                                  \
  namespace snag::cuda {                                                            \
  void point_stream_trace_##unit(TraceRecord* records) {                            \
    SNAG_CUDA_CHECK(cudaMemcpyToSymbol(g_trace_records, &records, sizeof records)); \
  }                                                                                 \
  }
#else
#define SNAG_CUDA_TRACE_UNIT(unit)
#endif

}  // namespace snag::cuda
