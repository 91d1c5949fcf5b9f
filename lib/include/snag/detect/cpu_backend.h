// The CPU backend: the paper's tree and traversal with OpenMP, one task per leaf.
#pragma once

#include <memory>

#include "snag/detect/backend.h"

namespace snag::detect {

/// How many leaves walk the tree together in the CPU's traversal (bvh/leaf_lanes.h): 8 where the
/// CPU has AVX2 (one 32-byte compare per box test), else 4 (`automatic`); `four` and `eight`
/// force a width (eight without AVX2 is correct but slow), for tests and benchmarks.
enum class CpuWalkWidth { automatic, four, eight };

/// The group width `width` gives on this machine: 4 or 8.
int cpu_walk_lanes(CpuWalkWidth width = CpuWalkWidth::automatic);

/// `threads` <= 0 uses OpenMP's default (all cores).
std::unique_ptr<Backend> make_cpu_backend(int threads = 0,
                                          CpuWalkWidth width = CpuWalkWidth::automatic);

}  // namespace snag::detect
