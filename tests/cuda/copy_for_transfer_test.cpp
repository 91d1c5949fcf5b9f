// copy_for_transfer (cuda/src/host_staging.cuh), the copy into pinned memory with streaming
// stores, against memcpy: every target and source alignment within 32 bytes, every size up to
// 300 bytes and a few large ones, with guard bytes around the target. Host memory only: runs
// without a GPU.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "host_staging.cuh"

namespace snag::test {
namespace {

TEST(CopyForTransfer, CopiesExactlyWhateverTheAlignmentAndSize) {
  std::mt19937 rng(7);
  std::vector<unsigned char> source(70000), target(70100), expected(70100);
  for (unsigned char& c : source) c = static_cast<unsigned char>(rng());
  std::vector<size_t> sizes;
  for (size_t n = 0; n <= 300; ++n) sizes.push_back(n);
  for (size_t n : {4095, 4096, 4097, 65536, 69999}) sizes.push_back(n);
  // The buffers' own alignment: offsets from a 64-byte boundary.
  const auto aligned = [](const unsigned char* p) {
    return static_cast<size_t>((64 - reinterpret_cast<uintptr_t>(p) % 64) % 64);
  };
  const size_t target_base = aligned(target.data()), source_base = aligned(source.data());
  for (size_t to = 0; to < 32; ++to)
    for (size_t from = 0; from < 32; ++from)
      for (size_t n : sizes) {
        if (source_base + from + n > source.size() || target_base + to + n + 8 > target.size())
          continue;
        for (size_t i = 0; i < target.size(); ++i)
          target[i] = expected[i] = static_cast<unsigned char>(i * 31);
        unsigned char* out = target.data() + target_base + to;
        const unsigned char* in = source.data() + source_base + from;
        cuda::copy_for_transfer(out, in, n);
        std::memcpy(expected.data() + target_base + to, in, n);
        ASSERT_EQ(target, expected)
            << "target offset " << to << ", source offset " << from << ", " << n << " bytes";
      }
}

}  // namespace
}  // namespace snag::test
