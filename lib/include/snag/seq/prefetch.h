// Reading frames ahead of the checker: reader threads parse the next frames while the current
// one is checked, at most `depth` frames held at once (read or being read, not yet taken), so
// memory stays bounded whatever the sequence length. Frames come out in sequence order; a
// reader's error (a bad file) is thrown by next() at that frame's turn, in order, so what the
// user sees does not depend on thread timing.
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "snag/mesh/mesh.h"
#include "snag/seq/sequence.h"

namespace snag::seq {

/// Reads items (one per frame: a mesh, or a scene's meshes) ahead of their consumer.
template <class Item>
class Prefetcher {
 public:
  struct Prefetched {
    size_t index = 0;  ///< position in the frame list
    Item item;
    double read_seconds = 0;  ///< the reader's time for this frame
  };

  /// Reads one frame; `reader` (0 .. readers - 1) says which thread calls, so that each can
  /// keep state of its own (an io::FrameReader).
  using Reader = std::function<Item(const Frame&, int reader)>;

  /// Starts `readers` threads (>= 1) reading `frames` in order with `read`, keeping at most
  /// `depth` (>= 1) frames ahead of the consumer.
  Prefetcher(std::vector<Frame> frames, int readers, int depth, Reader read)
      : frames_(std::move(frames)),
        read_(std::move(read)),
        depth_(static_cast<size_t>(std::max(depth, 1))),
        slots_(depth_) {
    const int count = std::max(1, std::min<int>(readers, static_cast<int>(depth_)));
    for (int t = 0; t < count; ++t) threads_.emplace_back([this, t] { read_loop(t); });
  }
  /// Stops the readers (frames being read are finished and dropped) and joins them.
  ~Prefetcher() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    slot_free_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  Prefetcher(const Prefetcher&) = delete;
  Prefetcher& operator=(const Prefetcher&) = delete;

  /// The next frame in order; nullopt after the last. Rethrows the reader's exception for
  /// that frame.
  std::optional<Prefetched> next() {
    std::unique_lock lock(mutex_);
    if (next_to_take_ >= frames_.size()) return std::nullopt;
    Slot& slot = slots_[next_to_take_ % depth_];
    frame_ready_.wait(lock, [&] { return slot.ready; });
    Slot taken = std::move(slot);
    slot = Slot{};
    ++next_to_take_;
    --held_;
    lock.unlock();
    slot_free_.notify_all();
    if (taken.error) std::rethrow_exception(taken.error);
    return std::move(taken.frame);
  }

  /// The most frames held at once so far (<= depth): what the memory bound is counted in.
  int peak_held() const {
    std::lock_guard lock(mutex_);
    return peak_held_;
  }

 private:
  struct Slot {
    bool ready = false;
    Prefetched frame;
    std::exception_ptr error;
  };

  void read_loop(int reader) {
    for (;;) {
      size_t index;
      {
        std::unique_lock lock(mutex_);
        // A frame may be claimed once its slot is free: fewer than depth frames ahead of the
        // consumer.
        slot_free_.wait(lock, [&] {
          return stopping_ || next_to_read_ >= frames_.size() ||
                 next_to_read_ < next_to_take_ + depth_;
        });
        if (stopping_ || next_to_read_ >= frames_.size()) return;
        index = next_to_read_++;
        peak_held_ = std::max(peak_held_, ++held_);
      }
      Slot result;
      const auto started = std::chrono::steady_clock::now();
      try {
        result.frame.item = read_(frames_[index], reader);
      } catch (...) {
        result.error = std::current_exception();
      }
      result.frame.index = index;
      result.frame.read_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      result.ready = true;
      {
        std::lock_guard lock(mutex_);
        slots_[index % depth_] = std::move(result);
      }
      frame_ready_.notify_all();
    }
  }

  std::vector<Frame> frames_;
  Reader read_;
  size_t depth_;
  mutable std::mutex mutex_;
  std::condition_variable slot_free_;    // readers wait for room
  std::condition_variable frame_ready_;  // the consumer waits for its frame
  std::vector<Slot> slots_;              // frame i lives in slots_[i % depth_]
  size_t next_to_read_ = 0;              // the next frame a reader claims
  size_t next_to_take_ = 0;              // the next frame next() returns
  int held_ = 0, peak_held_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

/// Meshes of a sequence's frames.
using FramePrefetcher = Prefetcher<mesh::Mesh>;
using PrefetchedFrame = FramePrefetcher::Prefetched;

}  // namespace snag::seq
