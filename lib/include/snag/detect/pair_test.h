// The narrow phase of one candidate pair (two triangles whose boxes overlap), run by both
// backends: each triangle tests the edges it represents against the other triangle.
#pragma once

#include <cstdint>

#include "snag/detect/exact.h"
#include "snag/detect/fan.h"
#include "snag/detect/topology.h"
#include "snag/geom/hd.h"
#include "snag/geom/narrow_phase.h"

namespace snag::detect {

/// Whether the pair is tested by the neighbour pass (it shares a listed vertex, see
/// Topology::neighbor_pairs) rather than from the traversal.
SNAG_HD_INLINE bool is_listed_neighbor(const geom::Tri& t, const geom::Tri& x,
                                       const uint8_t* listed_vertex, bool every_vertex_listed) {
  if (every_vertex_listed) {  // the usual case: sharing any vertex is enough
    bool shared = false;
    for (int i = 0; i < 3; ++i)
      shared |= (t.v[i] == x.v[0]) | (t.v[i] == x.v[1]) | (t.v[i] == x.v[2]);
    return shared;
  }
  bool listed = false;
  for (int i = 0; i < 3; ++i) {
    const bool shared = (t.v[i] == x.v[0]) | (t.v[i] == x.v[1]) | (t.v[i] == x.v[2]);
    if (shared) listed |= listed_vertex[t.v[i]] != 0;
  }
  return listed;
}

/// Which corners of `t` are vertices of `x` (bit i for corner i of t) and which corners of `x`
/// are vertices of `t`, from the nine id comparisons combined without branches.
SNAG_HD_INLINE void shared_corners(const geom::Tri& t, const geom::Tri& x, uint32_t& t_shared,
                                   uint32_t& x_shared) {
  uint32_t equal = 0;  // bit 3 i + j: t.v[i] == x.v[j]
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) equal |= static_cast<uint32_t>(t.v[i] == x.v[j]) << (3 * i + j);
  t_shared =
      ((equal & 7u) != 0) | (((equal >> 3) & 7u) != 0) << 1 | (((equal >> 6) & 7u) != 0) << 2;
  const uint32_t columns = equal | (equal >> 3) | (equal >> 6);
  x_shared = columns & 7u;
}

/// Whether the corners of `t` that `x` does not share (`shared`: shared_corners(t, x)) all lie
/// strictly on one side of x's plane. Then t meets x's plane only in the shared corners, so
/// the pair cannot intersect beyond them and no edge of either can hit the other: every test
/// of the pair is ruled out. (Shared corners count as on the plane by topology; a corner on it
/// by geometry does not.) This rejects most pairs of neighbouring triangles after one or two
/// orientation tests.
SNAG_HD_INLINE bool separated(const geom::Sign side[3], uint32_t shared) {
  geom::Sign common = geom::Sign::zero;
  for (int i = 0; i < 3; ++i) {
    if (shared & (1u << i)) continue;
    if (side[i] != geom::Sign::positive && side[i] != geom::Sign::negative) return false;
    if (common == geom::Sign::zero)
      common = side[i];
    else if (side[i] != common)
      return false;
  }
  return common != geom::Sign::zero;
}

/// Calls f(k, edge) for each edge k (corners k, k + 1) of `t` that t represents (`owned`) and
/// that is not an edge of `x` too (`shared`: t's corners that are x's vertices): the
/// edge-triangle tests of t's side of the pair (t, x).
template <class F>
SNAG_HD_INLINE void for_each_tested_edge(const TopologyView& topo, int32_t t, uint8_t owned,
                                         uint32_t shared, F&& f) {
  for (int k = 0; k < 3; ++k) {
    if (!(owned & (1u << k))) continue;
    const uint32_t edge_corners = (1u << k) | (1u << ((k + 1) % 3));
    if ((shared & edge_corners) == edge_corners) continue;  // an edge of x itself
    f(k, topo.triangle_edges[t][k]);
  }
}

/// Tests the edges triangle `t` represents against triangle `x`; `side` holds t's corners'
/// sides w.r.t. x's plane.
template <class P, class Sink>
SNAG_HD_INLINE void test_owned_edges(const P& pred, const TopologyView& topo, int32_t t,
                                     const geom::Tri& tt, uint8_t owned, uint32_t shared, int32_t x,
                                     const geom::Tri& xt, const geom::Sign side[3], Sink& sink) {
  for_each_tested_edge(topo, t, owned, shared, [&](int k, int32_t edge) {
    const int32_t p = tt.v[k], q = tt.v[(k + 1) % 3];
    switch (geom::edge_hits_triangle(pred, p, q, xt, side[k], side[(k + 1) % 3])) {
      case geom::Answer::yes:
        sink.hit(edge, x);
        break;
      case geom::Answer::uncertain:
        sink.uncertain(edge, x);
        break;
      case geom::Answer::no:
        sink.miss();
        break;
    }
  });
}

/// Reports the answers of straddling_edge_hits (`hits`, by edge of t, none uncertain) for the
/// edges triangle `t` tests against `x`, as test_owned_edges would report them.
template <class Sink>
SNAG_HD_INLINE void report_owned_edges(const TopologyView& topo, int32_t t, uint8_t owned,
                                       uint32_t shared, int32_t x, const geom::Answer hits[3],
                                       Sink& sink) {
  for_each_tested_edge(topo, t, owned, shared, [&](int k, int32_t edge) {
    if (hits[k] == geom::Answer::yes)
      sink.hit(edge, x);
    else
      sink.miss();
  });
}

/// What the pair tests read of one frame: the positions and every triangle's plane
/// (PlaneCoefficients::of its corners), computed once per frame, and optionally which
/// vertices' fans are clear (fan_is_clear; null: none is taken as clear).
struct FrameView {
  const geom::Vec3d* positions = nullptr;
  const geom::PlaneCoefficients* planes = nullptr;
  const uint8_t* fan_clear = nullptr;
};

SNAG_HD_INLINE geom::PlaneCoefficients triangle_plane(const geom::Vec3d* positions,
                                                      const geom::Tri& t) {
  return geom::PlaneCoefficients::of(positions[t.v[0]], positions[t.v[1]], positions[t.v[2]]);
}

/// The sides of t's corners w.r.t. the plane of triangle x (`plane`): zero for the corners
/// in `shared` (vertices of x); orient3d(x0, x1, x2, corner) otherwise, bit for bit.
SNAG_HD_INLINE void sides_against(const geom::Vec3d* positions,
                                  const geom::PlaneCoefficients& plane, const geom::Tri& t,
                                  uint32_t shared, const geom::Tri& x, geom::Sign side[3]) {
  const geom::Vec3d origin = positions[x.v[0]];
  for (int i = 0; i < 3; ++i) {
    if (shared & (1u << i)) {
      side[i] = geom::Sign::zero;
      continue;
    }
    const geom::Vec3d d = positions[t.v[i]];
    double perm;
    side[i] = geom::plane_side_filter(plane, origin, d, perm);
    if (side[i] == geom::Sign::uncertain)
      side[i] =
          geom::detail::plane_side_rare(origin, positions[x.v[1]], positions[x.v[2]], d, perm);
  }
}

/// The rejection by sides of the pair (t, x) (triangles tt, xt; shared corners t_shared,
/// x_shared): true when all of one triangle's corners not shared with the other lie strictly on
/// one side of the other's plane, so that the two cannot meet beyond their shared corners. Fills
/// side_t (t's corners against x's plane) and, when t's are not separated, side_x.
SNAG_HD_INLINE bool separated_by_sides(const FrameView& frame, int32_t t, const geom::Tri& tt,
                                       uint32_t t_shared, int32_t x, const geom::Tri& xt,
                                       uint32_t x_shared, geom::Sign side_t[3],
                                       geom::Sign side_x[3]) {
  sides_against(frame.positions, frame.planes[x], tt, t_shared, xt, side_t);
  if (separated(side_t, t_shared)) return true;
  sides_against(frame.positions, frame.planes[t], xt, x_shared, tt, side_x);
  return separated(side_x, x_shared);
}

/// The narrow phase of the candidate pair (t, x), neither degenerate, whose shared corners
/// are known (t_shared, x_shared: see shared_corners). Reports to `sink`:
///   hit(edge, triangle)       an edge meets a triangle beyond their shared endpoints: every
///                             face of the edge intersects the triangle;
///   uncertain(edge, triangle) the filter could not decide that test;
///   miss()                    a test decided `no` (counted);
///   duplicate(t, x)           the two share all three vertices (a duplicated face).
/// A pair sharing a vertex whose fan is clear (cleared_by_fan) ends at once; the rejection by
/// sides comes next: it settles most other pairs (96% of a cloth's neighbour pairs) before
/// anything else of the pair is loaded.
template <class Sink>
SNAG_HD void test_pair_given_shared(const FrameView& frame, const TopologyView& topo, int32_t t,
                                    int32_t x, uint32_t t_shared, uint32_t x_shared, Sink& sink) {
  const geom::Tri tt = topo.triangles[t], xt = topo.triangles[x];
  if (t_shared == 7u) {
    sink.duplicate(t, x);
    return;
  }
  if (cleared_by_fan(frame.fan_clear, tt, t_shared)) return;
  geom::Sign side_t[3], side_x[3];
  if (separated_by_sides(frame, t, tt, t_shared, x, xt, x_shared, side_t, side_x)) return;
  const uint8_t owned_t = topo.owned_edges[t], owned_x = topo.owned_edges[x];
  if (!(owned_t | owned_x)) return;
  const geom::FilteredPredicates pred{frame.positions};
  // Most pairs that get this far share no vertex and straddle each other's planes: their
  // edges are decided together, from two or four orientations where the edge tests ask six.
  if (t_shared == 0 && geom::strict_sides(side_t) && geom::strict_sides(side_x)) {
    geom::Answer t_hits[3], x_hits[3];
    if (geom::straddling_edge_hits(pred, tt, xt, side_t, side_x, t_hits, x_hits)) {
      report_owned_edges(topo, t, owned_t, t_shared, x, t_hits, sink);
      report_owned_edges(topo, x, owned_x, x_shared, t, x_hits, sink);
      return;
    }
  }
  if (owned_t) test_owned_edges(pred, topo, t, tt, owned_t, t_shared, x, xt, side_t, sink);
  if (owned_x) test_owned_edges(pred, topo, x, xt, owned_x, x_shared, t, tt, side_x, sink);
}

/// Whether test_pair_given_shared(frame, topo, t, x, t_shared, x_shared, ...) gets past the
/// rejections by fan and by sides, so that it has anything to report: false exactly when it
/// returns after them with no report (the same cleared_by_fan and separated_by_sides), so a
/// GPU can screen its pairs with it in a light kernel and hand only the rest to the full test.
SNAG_HD_INLINE bool pair_passes_sides(const FrameView& frame, const TopologyView& topo, int32_t t,
                                      int32_t x, uint32_t t_shared, uint32_t x_shared) {
  if (t_shared == 7u) return true;  // a duplicated face: reported as one
  const geom::Tri tt = topo.triangles[t];
  if (cleared_by_fan(frame.fan_clear, tt, t_shared)) return false;
  geom::Sign side_t[3], side_x[3];
  return !separated_by_sides(frame, t, tt, t_shared, x, topo.triangles[x], x_shared, side_t,
                             side_x);
}

/// The narrow phase of (t, x) with the filter left out (`--exact all`): every edge-triangle
/// test the pair needs is reported uncertain, for exact predicates to decide; no sign is
/// computed. Duplicated faces are found by their ids, as in test_pair_given_shared.
template <class Sink>
SNAG_HD void defer_pair_given_shared(const TopologyView& topo, int32_t t, int32_t x,
                                     uint32_t t_shared, uint32_t x_shared, Sink& sink) {
  if (t_shared == 7u) {
    sink.duplicate(t, x);
    return;
  }
  for_each_tested_edge(topo, t, topo.owned_edges[t], t_shared,
                       [&](int, int32_t edge) { sink.uncertain(edge, x); });
  for_each_tested_edge(topo, x, topo.owned_edges[x], x_shared,
                       [&](int, int32_t edge) { sink.uncertain(edge, t); });
}

/// The narrow phase of a pair whose shared corners are known, as `use` says.
template <FilterUse use, class Sink>
SNAG_HD_INLINE void test_pair(const FrameView& frame, const TopologyView& topo, int32_t t,
                              int32_t x, uint32_t t_shared, uint32_t x_shared, Sink& sink) {
  if constexpr (use == FilterUse::certify)
    test_pair_given_shared(frame, topo, t, x, t_shared, x_shared, sink);
  else
    defer_pair_given_shared(topo, t, x, t_shared, x_shared, sink);
}

/// The narrow phase of a candidate pair from the traversal (shared corners computed here).
template <FilterUse use = FilterUse::certify, class Sink>
SNAG_HD void test_candidate_pair(const FrameView& frame, const TopologyView& topo, int32_t t,
                                 int32_t x, Sink& sink) {
  uint32_t t_shared, x_shared;
  shared_corners(topo.triangles[t], topo.triangles[x], t_shared, x_shared);
  test_pair<use>(frame, topo, t, x, t_shared, x_shared, sink);
}

}  // namespace snag::detect
