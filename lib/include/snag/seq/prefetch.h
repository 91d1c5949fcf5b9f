// Reading frames ahead of the checker: reader threads parse the next frames while the current
// one is checked, at most `depth` frames held at once (read or being read, not yet taken), so
// memory stays bounded whatever the sequence length. Frames come out in sequence order; a
// reader's error (a bad file) is thrown by next() at that frame's turn, in order, so what the
// user sees does not depend on thread timing.
#pragma once

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

struct PrefetchedFrame {
  size_t index = 0;  ///< position in the frame list
  mesh::Mesh mesh;
  double read_seconds = 0;  ///< the reader's time for this frame
};

class FramePrefetcher {
 public:
  /// Reads one frame; `reader` (0 .. readers - 1) says which thread calls, so that each can
  /// keep state of its own (an io::FrameReader).
  using Reader = std::function<mesh::Mesh(const Frame&, int reader)>;

  /// Starts `readers` threads (>= 1) reading `frames` in order with `read`, keeping at most
  /// `depth` (>= 1) frames ahead of the consumer.
  FramePrefetcher(std::vector<Frame> frames, int readers, int depth, Reader read);
  /// Stops the readers (frames being read are finished and dropped) and joins them.
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  /// The next frame in order; nullopt after the last. Rethrows the reader's exception for
  /// that frame.
  std::optional<PrefetchedFrame> next();

  /// The most frames held at once so far (<= depth): what the memory bound is counted in.
  int peak_held() const;

 private:
  struct Slot {
    bool ready = false;
    PrefetchedFrame frame;
    std::exception_ptr error;
  };
  void read_loop(int reader);

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

}  // namespace snag::seq
