// The interface both backends implement: the CPU one in lib (OpenMP), the CUDA one in cuda/.
// Both run the same per-node, per-leaf and per-pair functions (snag/bvh, snag/geom headers).
#pragma once

#include <cstdint>
#include <memory>
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
  /// Per check run (in the order asked), the seconds of its traversal and narrow phase.
  std::vector<double> check_seconds;
};

/// Triangles of zero area as far as the filter can tell.
struct DegeneracyScan {
  std::vector<int32_t> degenerate;  ///< certainly zero area (sorted)
  std::vector<int32_t> uncertain;   ///< the filter cannot tell (sorted)
};

/// Every part of the topology, or every check: what the single-mesh calls below pass.
inline std::vector<int32_t> all_indices(int32_t count) {
  std::vector<int32_t> all(static_cast<size_t>(count));
  for (int32_t i = 0; i < count; ++i) all[i] = i;
  return all;
}

/// A frame's positions in a backend's staging memory (HostStaging::stage), held until the last
/// pointer to them is dropped.
class StagedPositions {
 public:
  virtual ~StagedPositions() = default;
  virtual std::span<const geom::Vec3d> positions() const = 0;
};

/// Host memory that a backend copies positions to its device from directly (page-locked memory
/// on a GPU, where any other span is first copied into such memory on the checker's thread:
/// 40-80 us for 18K vertices on the H100's and H200's hosts). A caller that stages a frame's
/// positions there on another thread, ahead of its check, and passes the staged span to
/// set_part_positions() and stage_part_positions(), takes that copy off the checker's thread.
/// stage() may be called from any thread, beside the backend's own calls.
class HostStaging {
 public:
  virtual ~HostStaging() = default;
  /// A copy of `positions` in staging memory; null when every buffer is held (that frame is
  /// then copied as any other). Never waits for a buffer to be given back.
  virtual std::shared_ptr<const StagedPositions> stage(std::span<const geom::Vec3d> positions) = 0;
};

/// A backend works on one topology of one or more parts (topology.h): one tree per part,
/// built, refit and measured part by part, and the topology's checks run as the caller picks
/// them, so that a part that did not move costs nothing.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string_view name() const = 0;
  /// A new topology, owned by the caller and valid until the next call.
  virtual void set_topology(const Topology& topology) = 0;
  /// This frame's positions (vertex_count entries); valid until the next call. `moved[p]` is 0
  /// for a part whose positions are the previous call's, bit for bit: a backend with memory of
  /// its own copies only the other parts across. Empty: every part moved.
  virtual void set_part_positions(std::span<const geom::Vec3d> positions,
                                  std::span<const uint8_t> moved) = 0;
  /// The next frame's positions, given while the current one is checked, so that a backend
  /// with memory of its own can copy them across meanwhile; a set_part_positions() with the
  /// same span (same address and size, contents unchanged since) then copies nothing. The span
  /// must stay valid and unchanged until the next set_part_positions() (the GPU backend reads
  /// it while the current frame's work runs); a different span then drops it unread. A hint:
  /// the CPU backend has nothing to copy, and a span never set is dropped; so is a `next` of
  /// another vertex count. `moved` as in set_part_positions, relative to the frame being
  /// checked; one of another length than the parts (the next frame's layout differs) counts as
  /// every part moved. An empty `next` forgets a frame
  /// staged before (a caller whose run stopped between staging a frame and setting it, and whose
  /// span may since hold something else).
  virtual void stage_part_positions(std::span<const geom::Vec3d> next,
                                    std::span<const uint8_t> moved) {
    (void)next;
    (void)moved;
  }
  /// Staging memory for up to `buffers` frames held at once (HostStaging), or null when this
  /// backend has nothing to copy (the CPU's). One per backend: later calls return the first's.
  virtual std::shared_ptr<HostStaging> host_staging(int buffers) {
    (void)buffers;
    return nullptr;
  }
  /// Triangles of these parts of zero area as far as the filter can tell.
  virtual DegeneracyScan scan_degenerate_parts(std::span<const int32_t> parts) = 0;
  /// Builds part p's tree over the current positions.
  virtual void build_part(int32_t part) = 0;
  /// Refits part p's tree to the current positions.
  virtual void refit_part(int32_t part) = 0;
  /// Part p's tree: sum of internal-node half areas over the root's half area (0 for a single
  /// triangle).
  virtual double part_quality(int32_t part) = 0;
  /// Traversal and the narrow phase of the topology's checks listed in `checks` (indices into
  /// Topology::checks, increasing); `degenerate` (sorted) are left out. With
  /// FilterUse::defer_all every edge-triangle test of every candidate pair is returned in
  /// `uncertain`, and `pairs` holds only duplicated faces (found by their ids).
  virtual FilteredFrame detect_checks(std::span<const int32_t> degenerate, FilterUse use,
                                      std::span<const int32_t> checks) = 0;

  // A single mesh (or every part and every check at once).
  void set_positions(std::span<const geom::Vec3d> positions) { set_part_positions(positions, {}); }
  void stage_positions(std::span<const geom::Vec3d> next) { stage_part_positions(next, {}); }
  DegeneracyScan scan_degenerate() { return scan_degenerate_parts(all_indices(part_count())); }
  void build() {
    for (int32_t p = 0; p < part_count(); ++p) build_part(p);
  }
  void refit() {
    for (int32_t p = 0; p < part_count(); ++p) refit_part(p);
  }
  /// The quality of the first part's tree: a single mesh's.
  double tree_quality() { return part_quality(0); }
  FilteredFrame detect(std::span<const int32_t> degenerate, FilterUse use = FilterUse::certify) {
    return detect_checks(degenerate, use, all_indices(check_count()));
  }

 protected:
  virtual int32_t part_count() const = 0;
  virtual int32_t check_count() const = 0;
};

}  // namespace snag::detect
