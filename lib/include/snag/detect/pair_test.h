// The narrow phase of one candidate pair (two triangles whose boxes overlap), run by both
// backends: each triangle tests the edges it represents against the other triangle.
#pragma once

#include <cstdint>

#include "snag/detect/topology.h"
#include "snag/geom/hd.h"
#include "snag/geom/narrow_phase.h"

namespace snag::detect {

SNAG_HD_INLINE int shared_vertex_count(const geom::Tri& a, const geom::Tri& b) {
  int shared = 0;
  for (int i = 0; i < 3; ++i) shared += (a.v[i] == b.v[0]) + (a.v[i] == b.v[1]) + (a.v[i] == b.v[2]);
  return shared;
}

SNAG_HD_INLINE bool is_corner_of(int32_t v, const geom::Tri& x) { return v == x.v[0] || v == x.v[1] || v == x.v[2]; }

/// Whether the corners of `t` that `x` does not share all lie strictly on one side of x's
/// plane. Then t meets x's plane only in the shared corners, so the pair cannot intersect
/// beyond them and no edge of either can hit the other: every test of the pair is ruled out.
/// (Shared corners count as on the plane by topology; a corner on it by geometry does not.)
/// This rejects most pairs of neighbouring triangles after one or two orientation tests.
SNAG_HD_INLINE bool separated(const geom::Sign side[3], const geom::Tri& t, const geom::Tri& x) {
  geom::Sign common = geom::Sign::zero;
  for (int i = 0; i < 3; ++i) {
    if (is_corner_of(t.v[i], x)) continue;
    if (side[i] != geom::Sign::positive && side[i] != geom::Sign::negative) return false;
    if (common == geom::Sign::zero) common = side[i];
    else if (side[i] != common) return false;
  }
  return common != geom::Sign::zero;
}

/// Tests the edges triangle `t` represents against triangle `x`; `side` holds t's corners'
/// sides w.r.t. x's plane.
template <class P, class Sink>
SNAG_HD_INLINE void test_owned_edges(const P& pred, const TopologyView& topo, int32_t t, const geom::Tri& tt,
                                     uint8_t owned, int32_t x, const geom::Tri& xt, const geom::Sign side[3],
                                     Sink& sink) {
  for (int k = 0; k < 3; ++k) {
    if (!(owned & (1u << k))) continue;
    const int32_t p = tt.v[k], q = tt.v[(k + 1) % 3];
    if (is_corner_of(p, xt) && is_corner_of(q, xt)) continue;  // an edge of x itself
    const int32_t edge = topo.triangle_edges[t][k];
    switch (geom::edge_hits_triangle(pred, p, q, xt, side[k], side[(k + 1) % 3])) {
      case geom::Answer::yes: sink.hit(edge, x); break;
      case geom::Answer::uncertain: sink.uncertain(edge, x); break;
      case geom::Answer::no: sink.miss(); break;
    }
  }
}

/// The narrow phase of the candidate pair (t, x), neither degenerate. Reports to `sink`:
///   hit(edge, triangle)       an edge meets a triangle beyond their shared endpoints: every
///                             face of the edge intersects the triangle;
///   uncertain(edge, triangle) the filter could not decide that test;
///   miss()                    a test decided `no` (counted);
///   duplicate(t, x)           the two share all three vertices (a duplicated face).
template <class P, class Sink>
SNAG_HD void test_candidate_pair(const P& pred, const TopologyView& topo, int32_t t, int32_t x, Sink& sink) {
  const geom::Tri tt = topo.triangles[t], xt = topo.triangles[x];
  if (shared_vertex_count(tt, xt) == 3) {
    sink.duplicate(t, x);
    return;
  }
  const uint8_t owned_t = topo.owned_edges[t], owned_x = topo.owned_edges[x];
  if (!owned_t && !owned_x) return;  // every edge of either is tested by its representative
  geom::Sign side_t[3], side_x[3];
  geom::corner_sides(pred, tt, xt, side_t);
  if (separated(side_t, tt, xt)) return;
  geom::corner_sides(pred, xt, tt, side_x);
  if (separated(side_x, xt, tt)) return;
  if (owned_t) test_owned_edges(pred, topo, t, tt, owned_t, x, xt, side_t, sink);
  if (owned_x) test_owned_edges(pred, topo, x, xt, owned_x, t, tt, side_x, sink);
}

}  // namespace snag::detect
