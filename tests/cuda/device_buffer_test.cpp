// DeviceBuffer (cuda/src/device_buffer.cuh): an allocation past the GPU's memory is an
// OutOfMemory saying how much did not fit and how much was free, and leaves no CUDA error
// pending for the next call. Without a GPU the test skips with a loud message.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "device_buffer.cuh"
#include "require_gpu.h"
#include "snag/error.h"

namespace snag::test {
namespace {

TEST(CudaDeviceBuffer, AllocationPastTheDevicesMemoryIsOutOfMemory) {
  SNAG_REQUIRE_GPU();
  cuda::DeviceBuffer<uint8_t> buffer;
  buffer.reserve(16);
  try {
    buffer.reserve(size_t{1} << 50);  // a pebibyte: more than any GPU holds
    FAIL() << "a pebibyte was allocated";
  } catch (const OutOfMemory& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("1073741824 MiB did not fit"), std::string::npos) << message;
    EXPECT_NE(message.find(" free)"), std::string::npos) << message;
  }
  EXPECT_EQ(buffer.capacity(), 0u) << "the old buffer was released before the attempt";
  EXPECT_EQ(cudaGetLastError(), cudaSuccess);
  buffer.reserve(64);  // the device is still usable
  EXPECT_EQ(buffer.capacity(), 64u);
}

}  // namespace
}  // namespace snag::test
