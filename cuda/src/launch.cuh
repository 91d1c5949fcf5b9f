// Launch helpers. One thread per item: the grid covers `count` items with blocks of 256
// threads, and the launch is checked at once (SNAG_CUDA_CHECK_LAUNCH). Chained launches: the
// per-frame kernels, one after another on the backend's stream, with Hopper's programmatic
// dependent launch.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <utility>

#include "cuda_check.cuh"
#include "trace.cuh"

namespace snag::cuda {

inline constexpr int kBlock = 256;
/// The walks' blocks: 36K triangles are only ~270 walks per SM of an H100, so blocks of 64
/// spread them evenly. (With the walk that also tested its pairs, blocks of 256 left a few SMs
/// with two blocks and the frame waited for them; the box-only walk is the same at 64, 128 and
/// 256, cuda/NOTES.md.)
inline constexpr int kNarrowBlock = 64;

template <class... Params, class... Args>
void launch(void (*kernel)(Params...), int64_t count, cudaStream_t stream, Args&&... args) {
  if (count <= 0) return;
  const auto blocks = static_cast<unsigned>((count + kBlock - 1) / kBlock);
  kernel<<<blocks, kBlock, 0, stream>>>(static_cast<Params>(args)...);
  SNAG_CUDA_CHECK_LAUNCH();
}

/// Whether launch_chained may let a kernel start before the one ahead of it has finished, on
/// the current device: compute capability 9.0 or later, and this build's kernels compiled from
/// PTX 9.0 or later. A kernel compiled for an older target (SNAG_CUDA_ARCHITECTURES 80, say,
/// then JIT-compiled for a Hopper) has no wait_for_previous_kernel() in it, and chaining it
/// would let it read its predecessor's results early. Asked of the driver once per device.
bool chained_launches_supported();

/// How many blocks of `kernel`, `block_threads` threads each, the current device runs at once:
/// its SMs times the kernel's occupancy (registers, shared memory). Asked of the driver once per
/// kernel and device.
unsigned resident_blocks(const void* kernel, int block_threads);

/// Launches `kernel` on `stream` allowed to start before the kernel ahead of it there has
/// finished (programmatic stream serialization): its blocks are scheduled while the previous
/// kernel's last blocks run, and each waits in wait_for_previous_kernel() until that kernel has
/// finished and its writes are visible. Between kernels of a frame this takes the launch's
/// latency (~2.5 us a kernel on an H100, cuda/NOTES.md v9) off the stream's critical path. A
/// kernel launched this way must call wait_for_previous_kernel() before it reads or writes
/// any memory another stream operation touches. After a copy, a memset or an event, or where
/// chained_launches_supported() is false, this is an ordinary launch.
template <class... Params, class... Args>
void launch_chained(void (*kernel)(Params...), dim3 grid, dim3 block, cudaStream_t stream,
                    Args&&... args) {
  cudaLaunchAttribute attribute{};
  attribute.id = cudaLaunchAttributeProgrammaticStreamSerialization;
  attribute.val.programmaticStreamSerializationAllowed = 1;
  cudaLaunchConfig_t config{};
  config.gridDim = grid;
  config.blockDim = block;
  config.stream = stream;
  config.attrs = &attribute;
  config.numAttrs = chained_launches_supported() ? 1 : 0;
  SNAG_CUDA_CHECK(cudaLaunchKernelEx(&config, kernel, static_cast<Params>(args)...));
}

/// launch() chained: one thread per item, blocks of kBlock.
template <class... Params, class... Args>
void launch_chained_items(void (*kernel)(Params...), int64_t count, cudaStream_t stream,
                          Args&&... args) {
  if (count <= 0) return;
  launch_chained(kernel, dim3(static_cast<unsigned>((count + kBlock - 1) / kBlock)), dim3(kBlock),
                 stream, std::forward<Args>(args)...);
}

/// The start of every kernel launched by launch_chained: waits until the kernel ahead of it
/// on the stream has finished and its writes are visible, then lets the kernel after it be
/// scheduled (its blocks then wait here in turn). A no-op for a kernel launched otherwise,
/// and on targets before compute capability 9.0. In a SNAG_CUDA_TRACE build, also where the
/// launch records itself (trace.cuh).
__device__ __forceinline__ void wait_for_previous_kernel() {
#if defined(SNAG_CUDA_TRACE)
  const unsigned long long began = trace_clock();
#endif
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
  asm volatile("griddepcontrol.wait;" ::: "memory");
  asm volatile("griddepcontrol.launch_dependents;" ::: "memory");
#endif
#if defined(SNAG_CUDA_TRACE)
  trace_launch(began);
#endif
}

}  // namespace snag::cuda
