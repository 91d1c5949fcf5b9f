// CGAL's own answer, for tests and benchmarks: Polygon_mesh_processing::self_intersections on
// the triangles as one mesh (Epick kernel), and its exact per-pair tests.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "snag/detect/result.h"
#include "snag/geom/vec3.h"

namespace snag::validators {

/// Intersecting triangle pairs (a < b, sorted) as CGAL's self_intersections reports them (its
/// default, sequential), with
/// the triangles' shared vertices taken from their ids. Zero-area triangles are left out
/// (snag reports them apart). Throws snag::InternalError when the triangles do not form a
/// mesh CGAL's halfedge structure can hold; then use `cgal_soup_self_intersections`.
std::vector<std::pair<int32_t, int32_t>> cgal_self_intersections(
    std::span<const geom::Vec3d> positions, std::span<const geom::Tri> triangles);

/// CGAL's self_intersections over a sequence that keeps one topology: the halfedge mesh is
/// built once and only its points change per frame, so a benchmark times CGAL's own work and
/// not the construction of its mesh. Faces of zero area in the first frame are left out for
/// the whole sequence (as cgal_self_intersections leaves them out of one frame).
class CgalSequence {
 public:
  /// Throws snag::InternalError when the triangles do not form a halfedge mesh.
  CgalSequence(std::span<const geom::Vec3d> positions, std::span<const geom::Tri> triangles);
  ~CgalSequence();
  CgalSequence(const CgalSequence&) = delete;
  CgalSequence& operator=(const CgalSequence&) = delete;

  /// Moves the mesh's vertices to this frame's positions (same count as at construction).
  void set_positions(std::span<const geom::Vec3d> positions);
  /// The intersecting pairs (triangle ids, a < b, sorted) of the current positions.
  std::vector<std::pair<int32_t, int32_t>> self_intersections() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The same rules (shared edge: coplanar and folded onto each other; shared vertex: the
/// opposite edge of one meets the other; else CGAL::do_intersect) decided pair by pair with
/// CGAL's predicates over CGAL's box intersection, with shared vertices taken from ids. Works
/// on any triangle soup, including non-manifold ones.
std::vector<std::pair<int32_t, int32_t>> cgal_soup_self_intersections(
    std::span<const geom::Vec3d> positions, std::span<const geom::Tri> triangles);

/// Pairs between two separate meshes A and B (a cloth and an obstacle), which share no
/// topology: every (i, j), i a triangle of A (indices into positions_a) and j one of B (into
/// positions_b), whose closed triangles share a point, decided by CGAL::do_intersect (exact
/// for the predicate) on candidates from CGAL's bipartite box intersection (closed boxes, so
/// exact contacts are candidates). Zero-area triangles of either mesh are left out (snag
/// reports them apart). Sorted by (i, j), no duplicates.
std::vector<std::pair<int32_t, int32_t>> cgal_pairs_between(
    std::span<const geom::Vec3d> positions_a, std::span<const geom::Tri> triangles_a,
    std::span<const geom::Vec3d> positions_b, std::span<const geom::Tri> triangles_b);

/// snag's pairs as CGAL's answers above give them: (a, b) ids, in the same order.
std::vector<std::pair<int32_t, int32_t>> pair_ids(std::span<const detect::FacePair> pairs);

/// One pair under those rules: do non-degenerate triangles f and g (shared vertices by id)
/// intersect beyond what their shared vertices explain?
bool cgal_faces_intersect(std::span<const geom::Vec3d> positions, const geom::Tri& f,
                          const geom::Tri& g);

/// The kind of an intersecting pair, from CGAL alone: `crossing` when each triangle has
/// corners strictly on both sides of the other's plane (CGAL::orientation) and CGAL's exact
/// construction of their intersection (Epeck) is a segment of positive length; else
/// `touching`. Independent of snag's four-sign derivation (geom::is_crossing).
detect::PairKind cgal_pair_kind(std::span<const geom::Vec3d> positions, const geom::Tri& f,
                                const geom::Tri& g);

}  // namespace snag::validators
