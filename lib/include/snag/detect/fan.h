// Fans cleared whole: the pairs of triangles around one vertex, decided together per frame
// instead of pair by pair (a cloth's neighbour pairs are most of its candidates, and in a
// smooth region none of them intersects). Run by both backends.
//
// Vertex v's fan t_0 .. t_{k-1}, t_i = (v, a_i, a_{i+1}) (Topology::fan_steps), is clear when
// there is a direction n such that, projected along n, (1) every t_i keeps the fan's turning
// sense: det[n, e_i, e_{i+1}] > 0 with e_i = a_i - v, and (2) the fan turns around v at most
// once: the angles from e_0 to e_1, e_2, ... stay below a whole turn. Then the projected
// triangles lie in wedges around v's image that meet only along the edges e_i, so two
// triangles of the fan meet only at v or along the edge they share: no pair of the fan
// intersects (BRIEF.md: faces sharing a vertex or an edge intersect only beyond it). The
// converse does not hold; a fan that is not clear (folded, wound twice, or a sign the filter
// cannot certify) has its pairs tested one by one, so nothing is decided here that the pair
// tests would decide otherwise.
//
// Every sign comes from the double filter of geom/predicates.h: each determinant has rows that
// are exact (n, whatever vector was computed) or one rounded difference of input coordinates
// (e_i), which is the form its bound covers; an uncertain sign leaves the fan not clear.
#pragma once

#include <cstdint>

#include "snag/detect/topology.h"
#include "snag/geom/hd.h"
#include "snag/geom/predicates.h"
#include "snag/geom/vec3.h"

namespace snag::detect {

/// Non-owning view of Topology::fan_begin and fan_steps (host and device).
struct FanView {
  const int32_t* begin = nullptr;
  const FanStep* steps = nullptr;
};

/// Whether vertex v's fan is clear in this frame (see above); false for a vertex without a fan.
/// `planes`: every triangle's PlaneCoefficients::of its corners, this frame.
///
/// n is the sum of the fan's triangle normals turned its way (planes' minors, rounded: any n
/// will do). Condition (1) is the sign of n . minor(t_i), flipped for a reversed t_i: det[e_i,
/// e_{i+1}, n] up to the triangle's corner order. Condition (2): with R_i the sign of det[e_0,
/// n, e_i] (= det[n, e_i, e_0]: negative while the angle from e_0 to e_i is in (0, pi), positive
/// in (pi, 2 pi)), the fan goes past a whole turn exactly when some wedge from e_i to e_{i+1},
/// 1 <= i (up to k - 2 for a closed fan, whose last wedge ends at e_0; k - 1 for an open one),
/// contains e_0's direction: R_i >= 0 and R_{i+1} <= 0. Each wedge being less than a half-turn
/// (condition 1), "R_i < 0 or R_{i+1} > 0" for each excludes it.
SNAG_HD inline bool fan_is_clear(const geom::Vec3d* positions,
                                 const geom::PlaneCoefficients* planes, FanView fans, int32_t v) {
  const int32_t begin = fans.begin[v], end = fans.begin[v + 1];
  if (end - begin < 3) return false;  // no fan (the shortest are 3 steps, open or closed)
  const bool closed = fans.steps[end - 1].face >= 0;
  const int32_t triangles_end = closed ? end : end - 1;
  geom::Vec3d n{0.0, 0.0, 0.0};
  for (int32_t i = begin; i < triangles_end; ++i) {
    const int32_t face = fans.steps[i].face;
    const geom::PlaneCoefficients& plane = planes[face >> 1];
    const geom::Vec3d normal{plane.minor[0], plane.minor[1], plane.minor[2]};
    n = (face & 1) ? n - normal : n + normal;
  }
  for (int32_t i = begin; i < triangles_end; ++i) {
    const int32_t face = fans.steps[i].face;
    double perm;
    const geom::Sign side = geom::row_side_filter(planes[face >> 1], n, perm);
    if (side != ((face & 1) ? geom::Sign::negative : geom::Sign::positive)) return false;
  }
  const geom::Vec3d center = positions[v];
  const geom::PlaneCoefficients turn =
      geom::PlaneCoefficients::of_rows(positions[fans.steps[begin].corner] - center, n);
  auto turn_side = [&](int32_t step) {
    double perm;
    return geom::row_side_filter(turn, positions[fans.steps[step].corner] - center, perm);
  };
  // The wedges to check start at steps begin + 1 .. end - 2 in both kinds of fan: a closed
  // fan's last corner starts its last wedge, an open fan's ends its last.
  geom::Sign before = turn_side(begin + 1);
  for (int32_t i = begin + 1; i < end - 1; ++i) {
    const geom::Sign after = turn_side(i + 1);
    if (before != geom::Sign::negative && after != geom::Sign::positive) return false;
    before = after;
  }
  return true;
}

/// Whether the pair (t, x), t_shared marking t's corners that are vertices of x (shared_corners),
/// shares a vertex whose fan is clear this frame (`fan_clear`: a byte per vertex, 1 when
/// fan_is_clear): then the pair cannot intersect. False when fan_clear is null.
SNAG_HD_INLINE bool cleared_by_fan(const uint8_t* fan_clear, const geom::Tri& t,
                                   uint32_t t_shared) {
  if (fan_clear == nullptr || t_shared == 0) return false;
  bool clear = false;
  for (int i = 0; i < 3; ++i)
    if (t_shared & (1u << i)) clear |= fan_clear[t.v[i]] != 0;
  return clear;
}

/// Whether all three corners of triangle t have clear fans this frame: then every pair of t
/// with a triangle sharing one of its vertices is cleared_by_fan. (fan_clear not null.)
SNAG_HD_INLINE bool corners_clear(const uint8_t* fan_clear, const geom::Tri& t) {
  return (fan_clear[t.v[0]] & fan_clear[t.v[1]] & fan_clear[t.v[2]]) != 0;
}

}  // namespace snag::detect
