// FramePrefetcher: frames come out in order, each once, whatever the readers' timing; no more
// than `depth` frames are ever held; a reader's error surfaces at its frame's turn; dropping
// the prefetcher early does not hang.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include "snag/seq/prefetch.h"

namespace snag::seq {
namespace {

std::vector<Frame> numbered(int n) {
  std::vector<Frame> frames;
  for (int i = 0; i < n; ++i) frames.push_back({i + 1, "frame" + std::to_string(i + 1) + ".obj"});
  return frames;
}

/// A "mesh" that records which frame it was read from, after a random delay.
mesh::Mesh slow_read(const Frame& f, std::atomic<int>& reading, std::atomic<int>& peak) {
  const int now = ++reading;
  for (int seen = peak.load(); now > seen && !peak.compare_exchange_weak(seen, now);) {
  }
  thread_local std::mt19937 rng(std::random_device{}());
  std::this_thread::sleep_for(std::chrono::microseconds(rng() % 400));
  mesh::Mesh m;
  m.positions.push_back({static_cast<double>(f.number), 0, 0});
  --reading;
  return m;
}

TEST(FramePrefetcher, FramesComeOutInOrderOnceEach) {
  for (int readers : {1, 2, 4}) {
    for (int depth : {1, 3, 8}) {
      std::atomic<int> reading{0}, peak{0};
      FramePrefetcher prefetcher(numbered(60), readers, depth,
                                 [&](const Frame& f, int) { return slow_read(f, reading, peak); });
      size_t expected = 0;
      while (auto next = prefetcher.next()) {
        ASSERT_EQ(next->index, expected) << readers << " readers, depth " << depth;
        ASSERT_EQ(next->item.positions.at(0).x, static_cast<double>(expected + 1));
        EXPECT_GE(next->read_seconds, 0.0);
        ++expected;
      }
      EXPECT_EQ(expected, 60u);
      EXPECT_FALSE(prefetcher.next());
      EXPECT_LE(peak.load(), std::min(readers, depth));
    }
  }
}

TEST(FramePrefetcher, HoldsNoMoreThanDepthFramesForASlowConsumer) {
  std::atomic<int> reading{0}, peak{0};
  FramePrefetcher prefetcher(numbered(200), 3, 4,
                             [&](const Frame& f, int) { return slow_read(f, reading, peak); });
  int taken = 0;
  while (auto next = prefetcher.next()) {
    if (taken++ % 20 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(taken, 200);
  // The readers fill every slot while the consumer sleeps, and never more.
  EXPECT_EQ(prefetcher.peak_held(), 4);
}

TEST(FramePrefetcher, AReadersErrorIsThrownAtItsFramesTurn) {
  FramePrefetcher prefetcher(numbered(30), 4, 6, [](const Frame& f, int) {
    if (f.number == 17) throw std::runtime_error("bad frame 17");
    mesh::Mesh m;
    m.positions.push_back({static_cast<double>(f.number), 0, 0});
    return m;
  });
  for (size_t i = 0; i < 16; ++i) {
    auto next = prefetcher.next();
    ASSERT_TRUE(next);
    ASSERT_EQ(next->index, i);
  }
  EXPECT_THROW(prefetcher.next(), std::runtime_error);
}

TEST(FramePrefetcher, DroppingItEarlyStopsTheReaders) {
  std::atomic<int> reads{0};
  {
    FramePrefetcher prefetcher(numbered(1000), 2, 3, [&](const Frame&, int) {
      ++reads;
      return mesh::Mesh{};
    });
    ASSERT_TRUE(prefetcher.next());
  }  // must return: readers waiting for room are woken and leave
  EXPECT_LE(reads.load(), 1 + 3);
}

TEST(FramePrefetcher, EachReaderThreadHasItsOwnIndex) {
  // Per-reader state (an io::FrameReader each) is safe only if an index belongs to one thread.
  std::mutex mutex;
  std::map<int, std::set<std::thread::id>> threads_of_index;
  {
    std::atomic<int> reading{0}, peak{0};
    FramePrefetcher prefetcher(numbered(200), 3, 5, [&](const Frame& f, int reader) {
      {
        std::lock_guard lock(mutex);
        threads_of_index[reader].insert(std::this_thread::get_id());
      }
      return slow_read(f, reading, peak);
    });
    while (prefetcher.next()) {
    }
  }
  std::set<std::thread::id> all;
  for (const auto& [index, threads] : threads_of_index) {
    EXPECT_GE(index, 0);
    EXPECT_LT(index, 3);
    EXPECT_EQ(threads.size(), 1u) << "index " << index;
    all.insert(threads.begin(), threads.end());
  }
  EXPECT_EQ(all.size(), threads_of_index.size());  // and a thread has one index
}

}  // namespace
}  // namespace snag::seq
