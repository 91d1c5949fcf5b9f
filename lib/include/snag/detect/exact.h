// The tests the double-precision filter could not certify, and the interface of whoever
// decides them exactly (validators/: CGAL's exact predicates).
#pragma once

#include <cstdint>
#include <span>

#include "snag/detect/result.h"
#include "snag/detect/topology.h"
#include "snag/geom/vec3.h"

namespace snag::detect {

/// Does edge `edge` meet triangle `triangle` outside the endpoints the two share by id?
struct EdgeTriangleTask {
  int32_t edge;
  int32_t triangle;
  friend bool operator==(const EdgeTriangleTask&, const EdgeTriangleTask&) = default;
};

/// Everything an exact decision reads: one frame's positions and its topology.
struct ExactContext {
  std::span<const geom::Vec3d> positions;
  const Topology* topology = nullptr;
};

class ExactResolver {
 public:
  virtual ~ExactResolver() = default;
  /// hit[i] = 1 when tasks[i]'s edge meets its triangle beyond their shared endpoints.
  virtual void edge_hits(const ExactContext& context, std::span<const EdgeTriangleTask> tasks,
                         std::span<uint8_t> hit) = 0;
  /// kinds[i] = the kind of the intersecting pair pairs[i].
  virtual void pair_kinds(const ExactContext& context, std::span<const FacePair> pairs,
                          std::span<PairKind> kinds) = 0;
  /// degenerate[i] = 1 when triangles[i] has zero area (collinear corners).
  virtual void degenerate(const ExactContext& context, std::span<const int32_t> triangles,
                          std::span<uint8_t> degenerate) = 0;
};

}  // namespace snag::detect
