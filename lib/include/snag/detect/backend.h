// The interface both backends implement: the CPU one in lib (OpenMP), the CUDA one in cuda/.
// Both run the same per-node, per-leaf and per-pair functions (snag/bvh, snag/geom headers).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "snag/detect/exact.h"
#include "snag/detect/result.h"
#include "snag/detect/topology.h"
#include "snag/geom/vec3.h"

namespace snag::detect {

/// A frame as far as the double filter takes it.
struct FilteredFrame {
  /// Pairs the filter found intersecting, sorted by (a, b), unique. kind_certain[i] says
  /// whether pairs[i].kind was certified; the others are decided exactly afterwards.
  std::vector<FacePair> pairs;
  std::vector<uint8_t> kind_certain;
  /// Edge-triangle tests the filter could not certify.
  std::vector<EdgeTriangleTask> uncertain;
  int64_t candidate_pairs = 0;
  int64_t filtered_tests = 0;
  double traverse_seconds = 0;
  double classify_seconds = 0;
};

/// Triangles of zero area as far as the filter can tell.
struct DegeneracyScan {
  std::vector<int32_t> degenerate;  ///< certainly zero area (sorted)
  std::vector<int32_t> uncertain;   ///< the filter cannot tell (sorted)
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string_view name() const = 0;
  /// A new topology, owned by the caller and valid until the next call.
  virtual void set_topology(const Topology& topology) = 0;
  /// This frame's positions (vertex_count entries); valid until the next call.
  virtual void set_positions(std::span<const geom::Vec3d> positions) = 0;
  /// The next frame's positions, given while the current one is checked, so that a backend
  /// with memory of its own can copy them across meanwhile; a set_positions() with the same
  /// span (same address and size, contents unchanged since) then copies nothing. A hint: the
  /// CPU backend has nothing to copy, and a span never set is dropped.
  virtual void stage_positions(std::span<const geom::Vec3d> next) { (void)next; }
  virtual DegeneracyScan scan_degenerate() = 0;
  /// Builds the tree over the current positions.
  virtual void build() = 0;
  /// Refits the tree to the current positions.
  virtual void refit() = 0;
  /// Sum of internal-node half areas over the root's half area (1 for a single triangle).
  virtual double tree_quality() = 0;
  /// Traversal and the narrow phase; `degenerate` (sorted) are left out. With
  /// FilterUse::defer_all every edge-triangle test of every candidate pair is returned in
  /// `uncertain`, and `pairs` holds only duplicated faces (found by their ids).
  virtual FilteredFrame detect(std::span<const int32_t> degenerate,
                               FilterUse use = FilterUse::certify) = 0;
};

}  // namespace snag::detect
