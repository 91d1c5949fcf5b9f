#include "launch.cuh"

#include <atomic>

namespace snag::cuda {

namespace {

/// Compiled with the same targets as every other kernel of the backend: its PTX version is
/// theirs.
__global__ void probe_kernel() {}

}  // namespace

bool chained_launches_supported() {
  // Per device: 0 not asked yet, 1 no, 2 yes. Asking twice at once gives the same answer.
  constexpr int kDevices = 64;
  static std::atomic<int> answers[kDevices];
  int device = 0;
  SNAG_CUDA_CHECK(cudaGetDevice(&device));
  if (device >= kDevices) return false;
  if (const int known = answers[device].load(std::memory_order_relaxed)) return known == 2;
  int major = 0;
  SNAG_CUDA_CHECK(cudaDeviceGetAttribute(&major, cudaDevAttrComputeCapabilityMajor, device));
  cudaFuncAttributes probe{};
  SNAG_CUDA_CHECK(cudaFuncGetAttributes(&probe, probe_kernel));
  const bool yes = major >= 9 && probe.ptxVersion >= 90 && probe.binaryVersion >= 90;
  answers[device].store(yes ? 2 : 1, std::memory_order_relaxed);
  return yes;
}

}  // namespace snag::cuda
