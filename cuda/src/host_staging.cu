#include "host_staging.cuh"

#include <algorithm>
#include <cstdint>
#include <cstring>
#if defined(__x86_64__)
#include <emmintrin.h>
#endif

namespace snag::cuda {

/// A frame's positions in one of the buffers, which comes back when this is dropped.
class PinnedStaging::Staged final : public detect::StagedPositions {
 public:
  Staged(std::shared_ptr<PinnedStaging> staging, Buffer* buffer, size_t count)
      : staging_(std::move(staging)), buffer_(buffer), count_(count) {}
  ~Staged() override { staging_->give_back(buffer_); }
  Staged(const Staged&) = delete;
  Staged& operator=(const Staged&) = delete;
  std::span<const geom::Vec3d> positions() const override {
    return {buffer_->memory.data(), count_};
  }

 private:
  std::shared_ptr<PinnedStaging> staging_;  // the buffers outlive every frame staged in them
  Buffer* buffer_;
  size_t count_;
};

PinnedStaging::PinnedStaging(int device, int buffers)
    : device_(device), most_buffers_(static_cast<size_t>(std::max(buffers, 1))) {}

std::shared_ptr<const detect::StagedPositions> PinnedStaging::stage(
    std::span<const geom::Vec3d> positions) {
  // Every call, not only those that allocate: a thread that never selected the device (a later
  // run's preparing thread, the buffers made already) would otherwise have its first CUDA call
  // below (the event's synchronize) start device 0's context.
  SNAG_CUDA_CHECK(cudaSetDevice(device_));
  Buffer* buffer = nullptr;
  {
    std::lock_guard lock(mutex_);
    for (const std::unique_ptr<Buffer>& b : buffers_)
      if (!b->held) {
        buffer = b.get();
        break;
      }
    if (!buffer && buffers_.size() < most_buffers_) {
      // Created on the calling thread (the preparing thread): on the backend's device.
      buffers_.push_back(std::make_unique<Buffer>());
      buffer = buffers_.back().get();
    }
    if (!buffer) return nullptr;
    buffer->held = true;
  }
  // Held now: no other thread writes the buffer's contents until it is given back, but the
  // checker's thread reads every buffer's address and capacity (find(), under mutex_), so
  // those change only under mutex_. On any failure below it is given back at once (the Staged
  // pointer does it).
  std::shared_ptr<const Staged> staged;
  try {
    staged = std::make_shared<const Staged>(shared_from_this(), buffer, positions.size());
  } catch (...) {
    give_back(buffer);
    throw;
  }
  buffer->read.synchronize();  // the last transfer out of it (long done, in a frame loop)
  if (positions.size() > buffer->memory.capacity()) {
    PinnedBuffer<geom::Vec3d> larger;  // allocated outside the lock: find() does not wait
    try {
      larger.reserve(positions.size());
    } catch (const InternalError&) {
      // Page-locked memory refused (a limit on locked memory, say): this frame goes unstaged,
      // transferred as any other, and the buffer comes back as it was.
      return nullptr;
    }
    {
      std::lock_guard lock(mutex_);
      buffer->memory.swap(larger);
    }
  }  // the smaller allocation is freed here, outside the lock
  if (!positions.empty())
    copy_for_transfer(buffer->memory.data(), positions.data(), positions.size_bytes());
  return staged;
}

void copy_for_transfer(void* to, const void* from, size_t bytes) {
#if defined(__x86_64__)
  auto* out = static_cast<char*>(to);
  const auto* in = static_cast<const char*>(from);
  // Up to the first 16-byte boundary of the target by memcpy, then 16 bytes a store.
  const size_t head = std::min(bytes, (16 - reinterpret_cast<uintptr_t>(out) % 16) % 16);
  std::memcpy(out, in, head);
  const size_t whole = head + (bytes - head) / 16 * 16;
  for (size_t i = head; i < whole; i += 16)
    _mm_stream_si128(reinterpret_cast<__m128i*>(out + i),
                     _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i)));
  _mm_sfence();  // the streamed stores are visible before the buffer is handed over
  std::memcpy(out + whole, in + whole, bytes - whole);
#else
  std::memcpy(to, from, bytes);
#endif
}

PinnedStaging::Buffer* PinnedStaging::find(const geom::Vec3d* data, size_t count) const {
  for (const std::unique_ptr<Buffer>& b : buffers_) {
    const geom::Vec3d* begin = b->memory.data();
    // Pointers into different allocations are compared as addresses (std::less is a total
    // order on pointers; the built-in < is not for unrelated ones).
    if (begin && !std::less<const geom::Vec3d*>()(data, begin) &&
        !std::less<const geom::Vec3d*>()(begin + b->memory.capacity(), data + count))
      return b.get();
  }
  return nullptr;
}

bool PinnedStaging::holds(std::span<const geom::Vec3d> positions) const {
  if (positions.empty()) return false;
  std::lock_guard lock(mutex_);
  return find(positions.data(), positions.size()) != nullptr;
}

void PinnedStaging::note_read(std::span<const geom::Vec3d> positions, cudaStream_t stream) {
  std::lock_guard lock(mutex_);
  if (Buffer* buffer = find(positions.data(), positions.size())) buffer->read.record(stream);
}

void PinnedStaging::give_back(Buffer* buffer) {
  std::lock_guard lock(mutex_);
  buffer->held = false;
}

}  // namespace snag::cuda
