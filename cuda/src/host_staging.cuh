// Page-locked buffers that a sequence's preparing thread copies each frame's positions into,
// ahead of its check, so that the GPU backend's transfer reads them directly instead of first
// copying the frame into pinned memory of its own on the checker's thread (detect::HostStaging).
//
// A buffer is held by the frame staged in it (the StagedPositions pointer) and comes back when
// that pointer is dropped; it is written again only once the last transfer the backend queued
// from it (note_read) is done. Buffers are allocated on first use, up to the count asked for,
// and grown when a frame needs more room; none is freed before the staging itself, which the
// backend holds for its life (a sequence loop asks for 7: 7 frames' positions of page-locked
// memory, 3 MB at 18K vertices).
#pragma once

#include <cuda_runtime.h>

#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "device_buffer.cuh"
#include "snag/detect/backend.h"

namespace snag::cuda {

/// `bytes` from `from` into pinned memory at `to` that the GPU's transfer reads next, not this
/// CPU: on x86-64 with streaming stores that bypass the caches, where an ordinary copy first
/// reads every line it writes (on the H200's host a frame of 18K vertices took ~60-80 us that
/// way); elsewhere memcpy.
void copy_for_transfer(void* to, const void* from, size_t bytes);

class PinnedStaging final : public detect::HostStaging,
                            public std::enable_shared_from_this<PinnedStaging> {
 public:
  /// Up to `buffers` buffers on `device`.
  PinnedStaging(int device, int buffers);

  std::shared_ptr<const detect::StagedPositions> stage(
      std::span<const geom::Vec3d> positions) override;

  /// Whether `positions` lie inside one of the buffers (a span staged here).
  bool holds(std::span<const geom::Vec3d> positions) const;
  /// After a transfer out of `positions` (a span this holds) was queued on `stream`: its buffer
  /// is not written again before that transfer is done.
  void note_read(std::span<const geom::Vec3d> positions, cudaStream_t stream);

 private:
  struct Buffer {
    PinnedBuffer<geom::Vec3d> memory;
    Event read;  ///< recorded after each transfer out of the buffer
    bool held = false;
  };
  class Staged;

  /// The buffer [data, data + count) lies in, or null. Under mutex_.
  Buffer* find(const geom::Vec3d* data, size_t count) const;
  void give_back(Buffer* buffer);

  int device_ = 0;
  size_t most_buffers_ = 0;
  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<Buffer>> buffers_;
};

}  // namespace snag::cuda
