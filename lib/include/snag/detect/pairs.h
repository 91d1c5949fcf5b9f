// Turning edge-triangle hits into face pairs and giving each pair its kind (host side; the
// CUDA backend does the same on the device with the same per-pair functions).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "snag/detect/exact.h"
#include "snag/detect/result.h"
#include "snag/detect/topology.h"
#include "snag/geom/predicates.h"

namespace snag::detect {

/// Every (face of the edge, triangle) pair of each hit, leaving out degenerate faces and the
/// triangle itself, as sorted unique pairs (a < b) of kind `touching` until classified. Up to
/// `threads` OpenMP threads share the work on large lists; the result is the same for any count.
std::vector<FacePair> expand_hits(const Topology& topology, std::span<const EdgeTriangleTask> hits,
                                  std::span<const uint8_t> degenerate_flags, int threads = 1);

/// Merges two sorted unique pair lists (kinds of `a` win on equal pairs), keeping a flag list
/// aligned with the result.
void merge_pairs(std::vector<FacePair>& into, std::vector<uint8_t>& into_flags,
                 std::span<const FacePair> more, std::span<const uint8_t> more_flags);

/// Sets each pair's kind with the double filter; certain[i] = 0 where the filter could not
/// tell (the caller decides those exactly). `planes`, when given, are the frame's triangle
/// planes (pair_test.h), saving their recomputation. Returns how many were uncertain.
int64_t classify_pairs(std::span<const geom::Vec3d> positions, const Topology& topology,
                       std::span<FacePair> pairs, std::vector<uint8_t>& certain, int threads,
                       const geom::PlaneCoefficients* planes = nullptr);

}  // namespace snag::detect
