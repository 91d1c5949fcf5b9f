#include "snag/seq/prefetch.h"

#include <algorithm>
#include <chrono>

namespace snag::seq {

FramePrefetcher::FramePrefetcher(std::vector<Frame> frames, int readers, int depth, Reader read)
    : frames_(std::move(frames)),
      read_(std::move(read)),
      depth_(static_cast<size_t>(std::max(depth, 1))),
      slots_(depth_) {
  const int count = std::max(1, std::min<int>(readers, static_cast<int>(depth_)));
  for (int t = 0; t < count; ++t) threads_.emplace_back([this, t] { read_loop(t); });
}

FramePrefetcher::~FramePrefetcher() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  slot_free_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void FramePrefetcher::read_loop(int reader) {
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
      result.frame.mesh = read_(frames_[index], reader);
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

std::optional<PrefetchedFrame> FramePrefetcher::next() {
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

int FramePrefetcher::peak_held() const {
  std::lock_guard lock(mutex_);
  return peak_held_;
}

}  // namespace snag::seq
