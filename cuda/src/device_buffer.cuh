// Owning device and pinned host buffers (RAII). Allocation happens when a topology or a
// sequence starts, or when a result buffer must grow; never per frame otherwise.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <utility>

#include "cuda_check.cuh"

namespace snag::cuda {

/// A device array of T. Growing discards the contents (callers fill it again).
template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(size_t count) { reserve(count); }
  ~DeviceBuffer() { release(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& other) noexcept { swap(other); }
  DeviceBuffer& operator=(DeviceBuffer&& other) noexcept {
    swap(other);
    return *this;
  }

  /// Makes room for at least `count` elements; contents are lost when it reallocates.
  void reserve(size_t count) {
    if (count <= capacity_) return;
    release();
    if (const cudaError_t status = cudaMalloc(&data_, count * sizeof(T)); status != cudaSuccess) {
      data_ = nullptr;  // release() must not free what the failed call left there
      throw_allocation_error(status, MemoryKind::device, count * sizeof(T),
                             "cudaMalloc(&data_, count * sizeof(T))", __FILE__, __LINE__);
    }
    capacity_ = count;
  }
  void swap(DeviceBuffer& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(capacity_, other.capacity_);
  }
  T* data() const { return data_; }
  size_t capacity() const { return capacity_; }

 private:
  void release() noexcept {
    if (data_) cudaFree(data_);  // a destructor cannot throw; a failed free leaks at worst
    data_ = nullptr;
    capacity_ = 0;
  }
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

/// A page-locked host array of T, the source and target of asynchronous copies.
template <class T>
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  ~PinnedBuffer() { release(); }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;

  void reserve(size_t count) {
    if (count <= capacity_) return;
    release();
    if (const cudaError_t status = cudaMallocHost(&data_, count * sizeof(T));
        status != cudaSuccess) {
      data_ = nullptr;  // release() must not free what the failed call left there
      throw_allocation_error(status, MemoryKind::pinned_host, count * sizeof(T),
                             "cudaMallocHost(&data_, count * sizeof(T))", __FILE__, __LINE__);
    }
    capacity_ = count;
  }
  T* data() const { return data_; }
  size_t capacity() const { return capacity_; }
  void swap(PinnedBuffer& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(capacity_, other.capacity_);
  }

 private:
  void release() noexcept {
    if (data_) cudaFreeHost(data_);
    data_ = nullptr;
    capacity_ = 0;
  }
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

/// The device address of pinned host memory (every cudaMallocHost allocation is mapped under
/// UVA): kernels write small results there directly, and the host reads them after the sync.
template <class T>
T* mapped(T* host) {
  void* device = nullptr;
  SNAG_CUDA_CHECK(cudaHostGetDevicePointer(&device, host, 0));
  return static_cast<T*>(device);
}

/// A stream and a pair of events owned together.
class Stream {
 public:
  Stream() { SNAG_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking)); }
  ~Stream() {
    if (stream_) cudaStreamDestroy(stream_);
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  cudaStream_t get() const { return stream_; }
  void synchronize() const { SNAG_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

 private:
  cudaStream_t stream_ = nullptr;
};

/// A CUDA event without timing, for ordering work between streams and with the host.
class Event {
 public:
  Event() { SNAG_CUDA_CHECK(cudaEventCreateWithFlags(&event_, cudaEventDisableTiming)); }
  ~Event() {
    if (event_) cudaEventDestroy(event_);
  }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  void record(cudaStream_t stream) { SNAG_CUDA_CHECK(cudaEventRecord(event_, stream)); }
  /// Makes `stream` wait (on the device) for the work before the last record().
  void wait_on(cudaStream_t stream) const {
    SNAG_CUDA_CHECK(cudaStreamWaitEvent(stream, event_, 0));
  }
  /// Waits on the host; returns at once when never recorded.
  void synchronize() const { SNAG_CUDA_CHECK(cudaEventSynchronize(event_)); }

 private:
  cudaEvent_t event_ = nullptr;
};

/// Times work on a stream with two CUDA events: start(), then stop() returns milliseconds
/// (it waits for the stream to reach the stop event).
class EventTimer {
 public:
  EventTimer() {
    SNAG_CUDA_CHECK(cudaEventCreate(&start_));
    if (const cudaError_t status = cudaEventCreate(&stop_); status != cudaSuccess) {
      cudaEventDestroy(start_);  // no destructor runs for an object whose constructor threw
      throw_cuda_error(status, "cudaEventCreate(&stop_)", __FILE__, __LINE__);
    }
  }
  ~EventTimer() {
    cudaEventDestroy(start_);
    cudaEventDestroy(stop_);
  }
  EventTimer(const EventTimer&) = delete;
  EventTimer& operator=(const EventTimer&) = delete;
  void start(cudaStream_t stream) { SNAG_CUDA_CHECK(cudaEventRecord(start_, stream)); }
  /// Records the stop without waiting for it (elapsed() waits).
  void stop_async(cudaStream_t stream) { SNAG_CUDA_CHECK(cudaEventRecord(stop_, stream)); }
  double elapsed() {
    SNAG_CUDA_CHECK(cudaEventSynchronize(stop_));
    float ms = 0;
    SNAG_CUDA_CHECK(cudaEventElapsedTime(&ms, start_, stop_));
    return ms;
  }
  cudaEvent_t start_event() const { return start_; }
  cudaEvent_t stop_event() const { return stop_; }
  double stop(cudaStream_t stream) {
    stop_async(stream);
    return elapsed();
  }

 private:
  cudaEvent_t start_ = nullptr, stop_ = nullptr;
};

}  // namespace snag::cuda
