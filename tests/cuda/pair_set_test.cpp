// The expansion's pair set (cuda/src/detect_kernels.cu, insert_pair) driven directly through
// launch_expand with hand-made buffers: a run whose distinct pairs outnumber the table's slots
// must end, counting past the pair capacity so that the host grows the buffers and runs the
// frame again. Through the backend a full table is hard to reach on purpose (a first frame past
// 65,536 hits on non-manifold edges or duplicated faces; cuda/NOTES.md); here it is a table of
// two slots. Without a GPU every test skips with a loud message.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <thread>
#include <vector>

#include "detect_kernels.cuh"
#include "device_buffer.cuh"
#include "require_gpu.h"

namespace snag::test {
namespace {

/// A book: four pages (triangles 0-3) on one spine edge from (0,0,-1) to (0,0,1), a
/// non-manifold edge, and triangle 4 in the plane z = 0 around the spine, which pierces it:
/// every page crosses triangle 4 (their intersection runs from the spine to triangle 4's
/// boundary).
struct Book {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
  static constexpr int32_t kPages = 4, kPierced = 4;
  static constexpr int kBits = 3;  // every id below 8

  Book() {
    positions = {{0, 0, -1}, {0, 0, 1}};
    for (int32_t page = 0; page < kPages; ++page) {
      const double angle = 0.4 + 1.5 * page;
      positions.push_back({std::cos(angle), std::sin(angle), 0});
      triangles.push_back({{0, 1, 2 + page}});
    }
    positions.push_back({-0.5, -0.5, 0});
    positions.push_back({0.6, -0.4, 0});
    positions.push_back({0.1, 0.7, 0});
    const auto first = static_cast<int32_t>(positions.size()) - 3;
    triangles.push_back({{first, first + 1, first + 2}});
  }
};

/// One launch_expand over device copies of the given hits (edge 0 is the spine, with the four
/// pages) and duplicated face pairs, into a pair set of `table_slots` slots (a power of two)
/// and `pair_capacity` pairs. Waits at most 20 s: a probe that never ends would leave the
/// device busy for good, so the test binary stops there, failing, rather than hang its run.
struct Expansion {
  cuda::FrameCounters counters{};
  std::vector<unsigned long long> table;
  std::vector<uint64_t> keys;
  std::vector<uint8_t> status;
};

Expansion expand(const Book& book, const std::vector<uint64_t>& hits,
                 const std::vector<uint64_t>& duplicates, unsigned long long table_slots,
                 unsigned long long pair_capacity) {
  const std::vector<int32_t> offsets = {0, Book::kPages};
  const std::vector<int32_t> faces = {0, 1, 2, 3};
  const std::vector<uint8_t> degenerate(book.triangles.size(), 0);
  cuda::DeviceBuffer<uint64_t> hit_buffer(std::max<size_t>(hits.size(), 1)),
      duplicate_buffer(std::max<size_t>(duplicates.size(), 1)), key_buffer(pair_capacity);
  cuda::DeviceBuffer<unsigned long long> table_buffer(table_slots);
  cuda::DeviceBuffer<uint8_t> status_buffer(pair_capacity), degenerate_buffer(degenerate.size());
  cuda::DeviceBuffer<int32_t> offset_buffer(offsets.size()), face_buffer(faces.size());
  cuda::DeviceBuffer<geom::Vec3d> position_buffer(book.positions.size());
  cuda::DeviceBuffer<geom::Tri> triangle_buffer(book.triangles.size());
  cuda::DeviceBuffer<cuda::FrameCounters> counter_buffer(1);
  const auto upload = [](auto& buffer, const auto& values) {
    SNAG_CUDA_CHECK(cudaMemcpy(buffer.data(), values.data(), values.size() * sizeof(values[0]),
                               cudaMemcpyHostToDevice));
  };
  upload(hit_buffer, hits);
  upload(duplicate_buffer, duplicates);
  upload(offset_buffer, offsets);
  upload(face_buffer, faces);
  upload(degenerate_buffer, degenerate);
  upload(position_buffer, book.positions);
  upload(triangle_buffer, book.triangles);
  cuda::FrameCounters counters{};
  counters.hits = hits.size();
  counters.duplicates = duplicates.size();
  upload(counter_buffer, std::vector<cuda::FrameCounters>{counters});
  SNAG_CUDA_CHECK(cudaMemset(table_buffer.data(), 0xff, table_slots * sizeof(unsigned long long)));
  static_assert(cuda::kEmptyKey == ~0ull, "the table is emptied with 0xff bytes");

  const cuda::PairSet set{table_buffer.data(), table_slots - 1, key_buffer.data(),
                          status_buffer.data(), pair_capacity};
  cudaStream_t stream = nullptr;
  SNAG_CUDA_CHECK(cudaStreamCreate(&stream));
  cuda::launch_expand(hit_buffer.data(), hits.size(), duplicate_buffer.data(), duplicates.size(),
                      2 * hits.size() + duplicates.size(), counter_buffer.data(),
                      offset_buffer.data(), face_buffer.data(), degenerate_buffer.data(),
                      Book::kBits, position_buffer.data(), triangle_buffer.data(), set,
                      /*max_blocks=*/4, stream);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  cudaError_t state = cudaErrorNotReady;
  while ((state = cudaStreamQuery(stream)) == cudaErrorNotReady &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (state == cudaErrorNotReady) {
    std::fprintf(stderr,
                 "FAILED: the expansion into a full pair set is still running after 20 s (its "
                 "probe does not end); stopping the test binary, whose later tests do not run\n");
    std::fflush(stderr);
    std::_Exit(1);
  }
  SNAG_CUDA_CHECK(state);
  SNAG_CUDA_CHECK(cudaStreamDestroy(stream));

  Expansion out;
  out.table.resize(table_slots);
  out.keys.resize(pair_capacity);
  out.status.resize(pair_capacity);
  SNAG_CUDA_CHECK(cudaMemcpy(&out.counters, counter_buffer.data(), sizeof(out.counters),
                             cudaMemcpyDeviceToHost));
  SNAG_CUDA_CHECK(cudaMemcpy(out.table.data(), table_buffer.data(),
                             table_slots * sizeof(unsigned long long), cudaMemcpyDeviceToHost));
  SNAG_CUDA_CHECK(cudaMemcpy(out.keys.data(), key_buffer.data(), pair_capacity * sizeof(uint64_t),
                             cudaMemcpyDeviceToHost));
  SNAG_CUDA_CHECK(
      cudaMemcpy(out.status.data(), status_buffer.data(), pair_capacity, cudaMemcpyDeviceToHost));
  return out;
}

uint64_t key(int32_t a, int32_t b) {
  return (uint64_t(a) << Book::kBits) | uint64_t(b);
}

/// The hit of the spine (edge 0) through triangle 4: one key per page.
const std::vector<uint64_t> kSpineHit = {(uint64_t{0} << 32) | Book::kPierced};
const std::set<uint64_t> kSpineKeys = {key(0, 4), key(1, 4), key(2, 4), key(3, 4)};

TEST(CudaPairSet, RoomyTableKeepsEachPairOnceWithItsKind) {
  SNAG_REQUIRE_GPU();
  // The hit twice (as two pair tests may report it) and a duplicated face pair: five distinct
  // keys in a table of 16 slots, each stored once; the pages all cross triangle 4.
  const Book book;
  const Expansion e = expand(book, {kSpineHit[0], kSpineHit[0]}, {(uint64_t{1} << 32) | 3}, 16, 8);
  EXPECT_EQ(e.counters.pairs, 5u);
  std::set<uint64_t> stored(e.keys.begin(), e.keys.begin() + 5);
  std::set<uint64_t> expected = kSpineKeys;
  expected.insert(key(1, 3));
  EXPECT_EQ(stored, expected);
  for (int i = 0; i < 5; ++i)
    if (e.keys[i] != key(1, 3))
      EXPECT_EQ(e.status[i], 2) << "pair " << (e.keys[i] >> 3) << "-" << (e.keys[i] & 7)
                                << ": certain crossing expected";
}

TEST(CudaPairSet, HitOnANonManifoldEdgeBeyondTheTableEndsAndCountsPastTheCapacity) {
  SNAG_REQUIRE_GPU();
  // One hit, four keys, two slots: the probe of the keys that find no slot must end, and the
  // count must exceed the pair capacity so that the host grows the buffers and runs again.
  const Book book;
  const Expansion e = expand(book, kSpineHit, {}, 2, 1);
  EXPECT_GT(e.counters.pairs, 1u);
  EXPECT_EQ(e.counters.pairs, 2u) << "each slot's key counted once, the others dropped";
  for (unsigned long long slot : e.table)
    EXPECT_TRUE(kSpineKeys.count(slot)) << "slot holds " << slot;
  EXPECT_NE(e.table[0], e.table[1]);
  EXPECT_TRUE(kSpineKeys.count(e.keys[0]));
}

TEST(CudaPairSet, DuplicatedFacesBeyondTheTableEndAndCountPastTheCapacity) {
  SNAG_REQUIRE_GPU();
  const Book book;
  const std::vector<uint64_t> duplicates = {(uint64_t{0} << 32) | 1, (uint64_t{0} << 32) | 2,
                                            (uint64_t{1} << 32) | 2};
  const Expansion e = expand(book, {}, duplicates, 2, 1);
  EXPECT_EQ(e.counters.pairs, 2u);
  const std::set<uint64_t> possible = {key(0, 1), key(0, 2), key(1, 2)};
  for (unsigned long long slot : e.table) EXPECT_TRUE(possible.count(slot)) << slot;
}

}  // namespace
}  // namespace snag::test
