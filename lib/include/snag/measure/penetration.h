// How deep cloth vertices sit inside a closed obstacle (a body, a collider), frame after frame.
//
// Method: for each point, the closest point on the obstacle's surface by a branch-and-bound
// walk of the obstacle's BVH (snag::bvh::Tree; nearer child first, a subtree skipped when the
// distance to its box is no less than the best so far), then the side from the sign of
// (point - closest) against the angle-weighted pseudonormal of the closest feature: the face
// normal when the closest point lies inside a face, the sum of the two face normals of an
// edge, the angle-weighted sum of the face normals around a vertex (Baerentzen and Aanaes,
// "Signed distance computation using the angle weighted pseudonormal", IEEE TVCG 2005). On a
// closed, consistently oriented, vertex-manifold surface that sign is exact for the exact
// closest point; in doubles it can only be wrong for points within rounding distance of the
// surface, whose depth is ~0, so the measure does not notice. Box distances are computed in
// double from the float boxes, which are rounded outward, so they are lower bounds (up to the
// rounding of a few operations, which only matters between features tied within it).
//
// Memory per obstacle triangle: 56 bytes for the tree (tree.h), 24 for its unit normal, 12
// for its corner indices, 12 for the triangles across its edges, 12 for the vertex-to-corner
// lists: about 116 bytes; per vertex, 24 for its position, 24 for its pseudonormal and 4 for
// the list offsets. (Copying each leaf's corners into leaf order, 72 more bytes per triangle,
// saved only 2-3% of measure()'s time on 10K and 360K triangles.)
// measure() allocates per call (the depths, when not given), never per point.
//
// Frame after frame most cloth vertices stay well clear of the body, and a vertex's distance
// to the surface can change by no more than the vertex moved plus the most any obstacle vertex
// moved (a surface point is a convex combination of its triangle's corners). So a Clearance
// remembers, per point, where it was last measured outside and how far from the surface; while
// its movement since then plus the obstacle's travel since then stays below that distance it is
// still outside (its winding number cannot change without the surface passing through it) and
// is not measured again. On a surface that does not intersect itself the result is the same as
// measuring every point. On one that does, the pseudonormal's side is ambiguous where the
// surface overlaps itself, and there a point's answer can depend on the frames measured before.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "snag/bvh/tree.h"
#include "snag/geom/vec3.h"

namespace snag::measure {

/// Why a triangle list is not a closed surface the meter can measure against, or nullopt when
/// it is. Closed means: at least one triangle, every corner index in [0, vertex_count), no
/// triangle repeats a vertex, every undirected edge is used by exactly two triangles, once in
/// each direction (watertight and consistently oriented), no two triangles use the same three
/// vertices (a triangle and its reverse pass the edge test), and the triangles around each vertex
/// form one fan (no pinch point, where two sheets meet at a single vertex and the vertex
/// pseudonormal would mix them). Vertices no triangle uses are allowed. The message names the
/// first problem found: bad corners in triangle order, then edges in increasing order of their
/// smaller, then larger, vertex, then repeated triangles, then pinch points in vertex order,
/// e.g.
/// "edge (12, 40) is used by 1 triangle (a hole): triangle 17",
/// "edge (3, 7) is used by 3 triangles: 2, 5, 9",
/// "triangles 5 and 9 orient edge (3, 7) the same way".
/// The meter takes each triangle's counter-clockwise side (right-hand rule over its corners)
/// as the outside: a closed surface listed inside out passes, and has a negative volume
/// (PenetrationMeter::enclosed_volume()).
std::optional<std::string> why_not_closed(std::span<const geom::Tri> triangles,
                                          int32_t vertex_count);

/// Summary of one measure() call. Depths are Euclidean distances to the surface, in the
/// coordinates' units.
struct PenetrationStats {
  int64_t points = 0;     ///< points measured
  int64_t inside = 0;     ///< points strictly inside the closed surface
  double ratio = 0;       ///< inside / points (0 when no points)
  double max_depth = 0;   ///< over the inside points; 0 when none is inside
  double mean_depth = 0;  ///< over the inside points, summed in point order; 0 when none
  double p95_depth = 0;   ///< 95th percentile of the inside points' depths, nearest-rank
                          ///< method: the ceil(0.95 k)-th smallest of the k depths; 0 when none
  int64_t proven_outside = 0;  ///< points a Clearance showed outside without a search
};

/// What earlier measure() calls of one meter proved about a list of points (a cloth's
/// vertices, frame after frame): per point, where it was last found outside and the obstacle
/// travel (PenetrationMeter::travel()) it could then take before it might reach the surface.
/// A Clearance belongs to one meter and one list length; given to another meter or another
/// length it starts over. Not shared between threads.
struct Clearance {
  std::vector<geom::Vec3d> anchor;  ///< where each point was last measured
  std::vector<double> reach;        ///< its distance then plus the travel then; -inf: re-measure
  const void* meter = nullptr;      ///< the meter whose travel `reach` counts from
};

/// Inside/outside and depth of points with respect to a closed obstacle surface. The meter is
/// made once per obstacle topology (it checks closedness and records edge and vertex
/// adjacency); update_positions() is called each frame the obstacle moves (the first call
/// builds the tree, later calls refit it); measure() takes the cloth's vertices. measure() is
/// const and may run from several threads at once.
class PenetrationMeter {
 public:
  /// `triangles` index into positions given to update_positions(), `vertex_count` of them.
  /// Throws snag::InternalError when why_not_closed() finds a problem: callers check first
  /// and report the message as an input error.
  PenetrationMeter(std::span<const geom::Tri> triangles, int32_t vertex_count);

  /// The obstacle's positions this frame (vertex_count of them, finite; copied). The first
  /// call builds the tree over them, later calls refit it (same tree, boxes recomputed), so
  /// the obstacle may move and deform freely. `threads` <= 0 uses OpenMP's default.
  /// Throws snag::InternalError on a wrong count.
  void update_positions(std::span<const geom::Vec3d> obstacle_positions, int threads = 0);

  /// Measures `points` against the surface at the last update_positions(), in parallel over
  /// points (`threads` <= 0 uses OpenMP's default). The result does not depend on the thread
  /// count. When `depths` is given it is resized to points.size() and receives each point's
  /// depth, 0 for points outside or on the surface (a point exactly on the surface is not
  /// inside; a non-finite point measures 0). Throws snag::InternalError before the first
  /// update_positions().
  PenetrationStats measure(std::span<const geom::Vec3d> points, int threads = 0,
                           std::vector<double>* depths = nullptr) const;

  /// measure(), skipping the points `clearance` proves are still outside, and updating it
  /// with what this call finds. The result is measure()'s on a surface that does not intersect
  /// itself (see the file comment); a point is skipped only with a margin against rounding:
  /// 1e-9 of its distance plus a few ulps of the coordinates' and the travel's magnitudes.
  PenetrationStats measure(std::span<const geom::Vec3d> points, Clearance& clearance,
                           int threads = 0, std::vector<double>* depths = nullptr) const;

  /// The sum over update_positions() calls of the largest distance any obstacle vertex moved
  /// in that call: an upper bound on how far any point of the surface has moved since an
  /// earlier call (0 after the first; NaN from a call with a non-finite position on, which
  /// proves nothing, so no point is skipped).
  double travel() const { return travel_; }

  /// The signed volume the surface encloses at the last update_positions() (0 before): positive
  /// when its triangles face outward, negative when the surface is inside out (then measure()
  /// reports the points outside it as inside; callers may warn). For a surface so small that
  /// its volume underflows, the smallest double of that sign.
  double enclosed_volume() const { return enclosed_volume_; }

  int32_t triangle_count() const { return static_cast<int32_t>(triangles_.size()); }
  int32_t vertex_count() const { return vertex_count_; }

 private:
  std::vector<geom::Tri> triangles_;
  int32_t vertex_count_ = 0;
  std::vector<int32_t> across_;             ///< 3 per triangle: the triangle across edge k,
                                            ///< from corner k to corner k + 1 (mod 3)
  std::vector<int32_t> corner_begin_;       ///< vertex_count + 1: CSR offsets into corners_
  std::vector<int32_t> corners_;            ///< 3 per triangle: corners (3 t + k) by vertex
  std::vector<geom::Vec3d> positions_;      ///< this frame's obstacle positions, times
                                            ///< 2^scale_exponent_ (the tree's, the normals')
  std::vector<geom::Vec3d> face_normal_;    ///< unit (zero for a zero-area triangle)
  std::vector<geom::Vec3d> vertex_normal_;  ///< angle-weighted sums of unit face normals
  bvh::Tree tree_{bvh::LeafBoxes::every_triangle};
  double enclosed_volume_ = 0;
  double travel_ = 0;
  double extent_ = 0;  ///< the largest coordinate magnitude of the positions, for the margin
  /// 0, or for an obstacle whose extent is past 2^100 or under 2^-100 the power of two that
  /// brings it to about 1: the measure works on positions and points scaled by it (exactly, a
  /// power of two) and scales distances back, so that no square or volume overflows.
  int scale_exponent_ = 0;
  bool built_ = false;

  PenetrationStats measure_points(std::span<const geom::Vec3d> points, Clearance* clearance,
                                  int threads, std::vector<double>* depths) const;
};

}  // namespace snag::measure
