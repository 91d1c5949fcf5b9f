// One-thread-per-item launches: the grid covers `count` items with blocks of 256 threads, and
// the launch is checked at once (SNAG_CUDA_CHECK_LAUNCH).
#pragma once

#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_check.cuh"

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

}  // namespace snag::cuda
