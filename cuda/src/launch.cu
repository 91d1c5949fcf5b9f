#include "launch.cuh"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <tuple>
#include <vector>

#include "snag/cuda/cuda_backend.h"

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

#if defined(SNAG_CUDA_TRACE)
void point_stream_trace_detect_kernels(TraceRecord* records);
void point_stream_trace_device_tree(TraceRecord* records);
#endif

bool stream_trace_compiled() {
#if defined(SNAG_CUDA_TRACE)
  return true;
#else
  return false;
#endif
}

void reset_stream_trace([[maybe_unused]] TraceRecord* records) {
#if defined(SNAG_CUDA_TRACE)
  const std::vector<TraceRecord> unused(kTraceSlots, TraceRecord{0, ~0ull, ~0ull, 0, 0});
  SNAG_CUDA_CHECK(cudaMemcpy(records, unused.data(), kTraceSlots * sizeof(TraceRecord),
                             cudaMemcpyHostToDevice));
  // A copy from pageable memory may return before it lands: the next launches must find it.
  SNAG_CUDA_CHECK(cudaDeviceSynchronize());
#endif
}

TraceRecord* stream_trace_buffer() {
#if defined(SNAG_CUDA_TRACE)
  constexpr int kDevices = 64;
  static std::mutex mutex;
  static TraceRecord* buffers[kDevices] = {};
  int device = 0;
  SNAG_CUDA_CHECK(cudaGetDevice(&device));
  if (device >= kDevices) return nullptr;
  const std::lock_guard lock(mutex);
  if (buffers[device] == nullptr) {
    TraceRecord* records = nullptr;
    SNAG_CUDA_CHECK(cudaMalloc(&records, kTraceSlots * sizeof(TraceRecord)));
    reset_stream_trace(records);
    point_stream_trace_detect_kernels(records);
    point_stream_trace_device_tree(records);
    SNAG_CUDA_CHECK(cudaDeviceSynchronize());
    buffers[device] = records;
  }
  return buffers[device];
#else
  return nullptr;
#endif
}

unsigned resident_blocks(const void* kernel, int block_threads) {
  struct Known {
    int device;
    const void* kernel;
    int block_threads;
    unsigned blocks;
  };
  static std::mutex mutex;
  static std::vector<Known> known;
  int device = 0;
  SNAG_CUDA_CHECK(cudaGetDevice(&device));
  const std::lock_guard lock(mutex);
  for (const Known& k : known)
    if (std::tie(k.device, k.kernel, k.block_threads) == std::tie(device, kernel, block_threads))
      return k.blocks;
  int per_sm = 0, sms = 0;
  SNAG_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  SNAG_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, block_threads, 0));
  const auto blocks = static_cast<unsigned>(std::max(per_sm, 1) * std::max(sms, 1));
  known.push_back({device, kernel, block_threads, blocks});
  return blocks;
}

}  // namespace snag::cuda
