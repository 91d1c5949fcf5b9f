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

SNAG_HD_INLINE bool all_strictly_one_side(const geom::Sign s[3]) {
  return (s[0] == geom::Sign::positive && s[1] == geom::Sign::positive && s[2] == geom::Sign::positive) ||
         (s[0] == geom::Sign::negative && s[1] == geom::Sign::negative && s[2] == geom::Sign::negative);
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
    const bool p_in_x = p == xt.v[0] || p == xt.v[1] || p == xt.v[2];
    const bool q_in_x = q == xt.v[0] || q == xt.v[1] || q == xt.v[2];
    if (p_in_x && q_in_x) continue;  // an edge of x itself
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
  // A triangle wholly on one side of the other's plane rules out every test of the pair.
  geom::Sign side_t[3], side_x[3];
  geom::corner_sides(pred, tt, xt, side_t);
  if (all_strictly_one_side(side_t)) return;
  geom::corner_sides(pred, xt, tt, side_x);
  if (all_strictly_one_side(side_x)) return;
  if (owned_t) test_owned_edges(pred, topo, t, tt, owned_t, x, xt, side_t, sink);
  if (owned_x) test_owned_edges(pred, topo, x, xt, owned_x, t, tt, side_x, sink);
}

}  // namespace snag::detect
