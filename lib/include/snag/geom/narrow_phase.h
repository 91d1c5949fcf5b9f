// The elementary decisions, written once over a predicate provider P (FilteredPredicates here;
// CGAL's exact predicates in validators/), run by both backends and by the exact resolver.
//
// P provides, on vertex ids:  Sign orient3d(a, b, c, d);  Sign orient2d(a, b, c, axis);
//                             int dominant_axis(a, b, c);
//                             plane(a, b, c) with Sign side(d) == orient3d(a, b, c, d).
//
// What counts as an intersection (BRIEF.md): two triangles intersect when their closed sets
// share a point that their shared vertices do not explain. For non-degenerate triangles F, X
// with shared vertex set S, F and X intersect iff F n X is not contained in conv(S). Because
// F n X is convex, that happens iff some extreme point of F n X lies outside conv(S); every
// extreme point lies on an edge of F (inside X) or on an edge of X (inside F). So:
//
//   F, X intersect  <=>  some edge e of F or X meets the other triangle outside the
//                        endpoints e shares with it (edge_hits_triangle below),
//
// and an edge's hit depends only on the edge and the triangle, not on which face of the edge
// is asked: a hit of e against X means every face incident to e intersects X. That is what
// lets each (edge, triangle) test be done once, by the edge's representative triangle.
// (Three shared vertices, a duplicated face, is the one case outside this and is reported by
// the caller as a touching pair.)
#pragma once

#include <cstdint>

#include "snag/geom/hd.h"
#include "snag/geom/predicates.h"
#include "snag/geom/vec3.h"

namespace snag::geom {

/// plane(a, b, c) for providers that have nothing to precompute per plane (the exact ones):
/// side(d) asks orient3d(a, b, c, d).
template <class P>
struct OrientPlane {
  const P* pred;
  int32_t a, b, c;
  Sign side(int32_t d) const { return pred->orient3d(a, b, c, d); }
};

/// A three-valued answer: uncertain when a sign the answer depends on was uncertain.
enum class Answer : int8_t { no = 0, yes = 1, uncertain = 2 };

SNAG_HD_INLINE Answer any_of(Answer a, Answer b) {
  if (a == Answer::yes || b == Answer::yes) return Answer::yes;
  if (a == Answer::uncertain || b == Answer::uncertain) return Answer::uncertain;
  return Answer::no;
}
SNAG_HD_INLINE Answer all_of(Answer a, Answer b) {
  if (a == Answer::no || b == Answer::no) return Answer::no;
  if (a == Answer::uncertain || b == Answer::uncertain) return Answer::uncertain;
  return Answer::yes;
}
SNAG_HD_INLINE Answer not_negative(Sign s) {
  return s == Sign::uncertain ? Answer::uncertain
                              : (s == Sign::negative ? Answer::no : Answer::yes);
}
/// s * t <= 0.
SNAG_HD_INLINE Answer opposite_or_zero(Sign s, Sign t) {
  if (s == Sign::zero || t == Sign::zero) return Answer::yes;
  if (s == Sign::uncertain || t == Sign::uncertain) return Answer::uncertain;
  return s != t ? Answer::yes : Answer::no;
}
/// s * t as a sign (t the orientation of a reference triangle, never zero).
SNAG_HD_INLINE Sign times(Sign s, Sign t) {
  if (s == Sign::uncertain || t == Sign::uncertain) return Sign::uncertain;
  return t == Sign::negative ? negate(s) : s;
}

/// Picks the projection axis for a triangle (a, b, c) and its orientation there: the
/// dominant axis, or the next with a nonzero exact component when the provider finds the
/// dominant one zero (possible only for the exact provider on a triangle of tiny area).
/// Returns Sign::uncertain when the filter cannot tell; Sign::zero only for a degenerate one.
template <class P>
SNAG_HD_INLINE Sign projection(const P& pred, int32_t a, int32_t b, int32_t c, int& axis) {
  const int first = pred.dominant_axis(a, b, c);
  for (int k = 0; k < 3; ++k) {
    axis = (first + k) % 3;
    const Sign s = pred.orient2d(a, b, c, axis);
    if (s != Sign::zero) return s;
  }
  return Sign::zero;
}

/// Closed point-in-triangle in the projection along `axis`; `orientation` is orient2d(a, b, c).
template <class P>
SNAG_HD_INLINE Answer point_in_triangle_2d(const P& pred, int32_t p, int32_t a, int32_t b,
                                           int32_t c, int axis, Sign orientation) {
  Answer inside = not_negative(times(pred.orient2d(a, b, p, axis), orientation));
  if (inside == Answer::no) return inside;
  inside = all_of(inside, not_negative(times(pred.orient2d(b, c, p, axis), orientation)));
  if (inside == Answer::no) return inside;
  return all_of(inside, not_negative(times(pred.orient2d(c, a, p, axis), orientation)));
}

/// Do closed segments pq and xy meet, given that neither p nor q lies in the triangle one of
/// whose edges is xy? Collinear overlap is then impossible without a vertex of the triangle
/// strictly inside pq, and that is found as a proper crossing of the triangle's other edge
/// through that vertex, so collinear pairs answer `no` here.
template <class P>
SNAG_HD_INLINE Answer segments_meet_2d(const P& pred, int32_t p, int32_t q, int32_t x, int32_t y,
                                       int axis) {
  const Sign o1 = pred.orient2d(p, q, x, axis), o2 = pred.orient2d(p, q, y, axis);
  if (o1 == Sign::zero && o2 == Sign::zero) return Answer::no;
  const Answer straddles_pq = opposite_or_zero(o1, o2);
  if (straddles_pq == Answer::no) return Answer::no;
  const Sign o3 = pred.orient2d(x, y, p, axis), o4 = pred.orient2d(x, y, q, axis);
  return all_of(straddles_pq, opposite_or_zero(o3, o4));
}

/// Does edge pq meet triangle t = (a, b, c) outside the endpoints it shares with t?
/// `sp`, `sq`: the sides of p and q w.r.t. t's plane (orient3d(a, b, c, .)), zero where the
/// endpoint is a vertex of t. Preconditions: t is not degenerate, pq is not an edge of t.
template <class P>
SNAG_HD Answer edge_hits_triangle(const P& pred, int32_t p, int32_t q, const Tri& t, Sign sp,
                                  Sign sq) {
  // Both endpoints strictly on one side: no contact.
  if ((sp == Sign::positive && sq == Sign::positive) ||
      (sp == Sign::negative && sq == Sign::negative))
    return Answer::no;
  const int32_t a = t.v[0], b = t.v[1], c = t.v[2];
  const bool p_shared = p == a || p == b || p == c;
  const bool q_shared = q == a || q == b || q == c;
  if (p_shared || q_shared) {
    // One shared endpoint s: the edge leaves t's corner s. Off the plane it meets t only at s;
    // in the plane it enters t iff its direction lies in t's closed angle at s.
    const int32_t s = p_shared ? p : q;
    const int32_t other = p_shared ? q : p;
    const Sign side = p_shared ? sq : sp;
    if (side == Sign::uncertain) return Answer::uncertain;
    if (side != Sign::zero) return Answer::no;
    // The corners of t after s, counterclockwise in t's own order.
    const int32_t s_next = s == a ? b : (s == b ? c : a);
    const int32_t s_prev = s == a ? c : (s == b ? a : b);
    int axis = 0;
    const Sign orientation = projection(pred, a, b, c, axis);
    if (orientation == Sign::uncertain) return Answer::uncertain;
    const Answer after_next =
        not_negative(times(pred.orient2d(s, s_next, other, axis), orientation));
    if (after_next == Answer::no) return Answer::no;
    return all_of(after_next,
                  not_negative(times(pred.orient2d(s, other, s_prev, axis), orientation)));
  }
  if (sp == Sign::uncertain || sq == Sign::uncertain) return Answer::uncertain;
  if (sp == Sign::zero && sq == Sign::zero) {
    // Coplanar: the segment meets the closed triangle iff an endpoint is inside it or the
    // segment crosses one of its edges, all in a projection that keeps the plane's incidences.
    int axis = 0;
    const Sign orientation = projection(pred, a, b, c, axis);
    if (orientation == Sign::uncertain) return Answer::uncertain;
    Answer hit = point_in_triangle_2d(pred, p, a, b, c, axis, orientation);
    if (hit == Answer::yes) return hit;
    hit = any_of(hit, point_in_triangle_2d(pred, q, a, b, c, axis, orientation));
    if (hit == Answer::yes) return hit;
    hit = any_of(hit, segments_meet_2d(pred, p, q, a, b, axis));
    if (hit == Answer::yes) return hit;
    hit = any_of(hit, segments_meet_2d(pred, p, q, b, c, axis));
    if (hit == Answer::yes) return hit;
    return any_of(hit, segments_meet_2d(pred, p, q, c, a, axis));
  }
  // The segment crosses or touches the plane at one point, inside the closed triangle iff the
  // line pq passes no edge of t on the opposite side from another: the three signs below
  // never include both a positive and a negative one.
  const Sign e0 = pred.orient3d(p, q, a, b);
  const Sign e1 = pred.orient3d(p, q, b, c);
  const Sign e2 = pred.orient3d(p, q, c, a);
  const bool has_positive = e0 == Sign::positive || e1 == Sign::positive || e2 == Sign::positive;
  const bool has_negative = e0 == Sign::negative || e1 == Sign::negative || e2 == Sign::negative;
  if (has_positive && has_negative) return Answer::no;
  if (e0 == Sign::uncertain || e1 == Sign::uncertain || e2 == Sign::uncertain)
    return Answer::uncertain;
  return Answer::yes;
}

/// Is triangle (a, b, c) of zero area (its corners collinear)? Exactly when its normal
/// vanishes, i.e. its projection along every axis has orientation zero.
template <class P>
SNAG_HD_INLINE Answer is_degenerate(const P& pred, int32_t a, int32_t b, int32_t c) {
  if (a == b || b == c || c == a) return Answer::yes;
  Answer degenerate = Answer::yes;
  for (int axis = 0; axis < 3; ++axis) {
    const Sign s = pred.orient2d(a, b, c, axis);
    if (s == Sign::positive || s == Sign::negative) return Answer::no;
    if (s == Sign::uncertain) degenerate = Answer::uncertain;
  }
  return degenerate;
}

/// The sides of triangle f's corners w.r.t. triangle x's plane; zero where a corner is a vertex of
/// x.
template <class P>
SNAG_HD_INLINE void corner_sides(const P& pred, const Tri& f, const Tri& x, Sign side[3]) {
  const auto plane = pred.plane(x.v[0], x.v[1], x.v[2]);
  for (int i = 0; i < 3; ++i) {
    const int32_t v = f.v[i];
    side[i] = (v == x.v[0] || v == x.v[1] || v == x.v[2]) ? Sign::zero : plane.side(v);
  }
}

/// Index of a corner alone on its strict side: no other corner on that side and at least one
/// strictly on the other. -1 when the triangle does not have corners strictly on both sides.
/// Sides must be certain.
SNAG_HD_INLINE int lone_corner(const Sign side[3]) {
  for (int i = 0; i < 3; ++i) {
    if (side[i] == Sign::zero) continue;
    const Sign next = side[(i + 1) % 3], prev = side[(i + 2) % 3];
    const Sign opposite = negate(side[i]);
    if (next != side[i] && prev != side[i] && (next == opposite || prev == opposite)) return i;
  }
  return -1;
}

/// Whether an intersecting pair is a crossing: not coplanar, each triangle has corners strictly
/// on both sides of the other's plane, and they share a segment of positive length.
///
/// With both straddling, f n plane(x) is a segment [I1, I2] of positive length with Ii on the
/// edge from f's lone corner f0 to corner fi (or at fi, when fi lies on the plane), and
/// likewise [J1, J2] for x from its lone corner x0. Along the line L where the planes meet,
/// orient3d(f0, fi, x0, xj) has the sign of pos(Jj) - pos(Ii) for one direction of L (the
/// product of the two normals, each turned towards the other triangle's lone corner): expand
/// x0 - f0 along (fi - f0), L and (xj - x0) and use that (fi - f0).n_x < 0 and
/// (xj - x0).n_f < 0. So the segments overlap in positive length iff some Ii < some Jj and
/// some Jj < some Ii: among the four signs there is a positive and a negative one.
/// sf: the sides of f's corners w.r.t. x's plane; sx: of x's w.r.t. f's (zero where shared).
template <class P>
SNAG_HD Answer is_crossing_given_sides(const P& pred, const Tri& f, const Tri& x, const Sign sf[3],
                                       const Sign sx[3]) {
  for (int i = 0; i < 3; ++i)
    if (sf[i] == Sign::uncertain || sx[i] == Sign::uncertain) return Answer::uncertain;
  const int fi = lone_corner(sf), xi = lone_corner(sx);
  if (fi < 0 || xi < 0) return Answer::no;  // coplanar or not straddling both ways
  const int32_t f0 = f.v[fi], f1 = f.v[(fi + 1) % 3], f2 = f.v[(fi + 2) % 3];
  const int32_t x0 = x.v[xi], x1 = x.v[(xi + 1) % 3], x2 = x.v[(xi + 2) % 3];
  // Two planes asked twice each (plane(a, b, c).side(d) is orient3d(a, b, c, d), with half the
  // coefficients computed); when I1 lies strictly between J1 and J2, the first plane's two
  // signs already differ and the second is not needed.
  const auto plane_1 = pred.plane(f0, f1, x0);
  const Sign order_1[2] = {plane_1.side(x1), plane_1.side(x2)};
  if ((order_1[0] == Sign::positive && order_1[1] == Sign::negative) ||
      (order_1[0] == Sign::negative && order_1[1] == Sign::positive))
    return Answer::yes;
  const auto plane_2 = pred.plane(f0, f2, x0);
  const Sign order[4] = {order_1[0], order_1[1], plane_2.side(x1), plane_2.side(x2)};
  bool positive = false, negative = false, uncertain = false;
  for (Sign s : order) {
    positive |= s == Sign::positive;
    negative |= s == Sign::negative;
    uncertain |= s == Sign::uncertain;
  }
  if (positive && negative) return Answer::yes;
  return uncertain ? Answer::uncertain : Answer::no;
}

/// Whether all three sides are certain and nonzero.
SNAG_HD_INLINE bool strict_sides(const Sign side[3]) {
  bool strict = true;
  for (int i = 0; i < 3; ++i) strict &= side[i] == Sign::positive || side[i] == Sign::negative;
  return strict;
}

/// edge_hits_triangle for every edge of f against x and of x against f at once, for two
/// triangles sharing no vertex whose corners lie strictly on both sides of the other's plane
/// (sf, sx: certain and nonzero, not all alike). f_hits[k] answers for f's edge k (corners k,
/// k + 1), x_hits[k] for x's. Returns false, leaving the answers unset, when a sign it needs is
/// uncertain (edge_hits_triangle, edge by edge, then decides).
///
/// With the lone corners f0 and x0 as in is_crossing_given_sides, the edge f0-fi crosses x's
/// plane at one point Ii and the edge f1-f2 does not reach it, so f0-fi hits x iff Ii lies in
/// x's segment [J1, J2] on the line L where the planes meet (likewise for x's edges against
/// [I1, I2]). Along the direction n_f x n_x of L, Jj - Ii has the sign of a b orient3d(f0, fi,
/// x0, xj), where a, b are the lone corners' sides, I2 - I1 that of -a and J2 - J1 that of b
/// (expand as in is_crossing_given_sides; the tests check these signs against the edge tests).
/// So the ends of both segments are ordered without arithmetic, two signs say whether the
/// segments meet (as in Guigue and Devillers' triangle test) and two more which ends lie in the
/// other segment: two or four orient3d over two planes, where the edge tests ask six.
template <class P>
SNAG_HD bool straddling_edge_hits(const P& pred, const Tri& f, const Tri& x, const Sign sf[3],
                                  const Sign sx[3], Answer f_hits[3], Answer x_hits[3]) {
  const int fl = lone_corner(sf), xl = lone_corner(sx);
  const int32_t f0 = f.v[fl], x0 = x.v[xl];
  const int32_t fi[3] = {f0, f.v[(fl + 1) % 3], f.v[(fl + 2) % 3]};
  const int32_t xj[3] = {x0, x.v[(xl + 1) % 3], x.v[(xl + 2) % 3]};
  const bool flip = sf[fl] != sx[xl];  // a b < 0
  // The lower and upper ends of each segment along L: I2 < I1 when a > 0, J1 < J2 when b > 0.
  const int i_low = sf[fl] == Sign::positive ? 2 : 1, i_high = 3 - i_low;
  const int j_low = sx[xl] == Sign::positive ? 1 : 2, j_high = 3 - j_low;
  const auto plane_low = pred.plane(f0, fi[i_low], x0);
  const auto plane_high = pred.plane(f0, fi[i_high], x0);
  // sign(Jj - Ii) for Ii from `plane` (that of f0, fi, x0).
  const auto order = [&](const auto& plane, int j) {
    const Sign s = plane.side(xj[j]);
    return flip ? negate(s) : s;
  };
  Answer low_i = Answer::no, high_i = Answer::no, low_j = Answer::no, high_j = Answer::no;
  const Sign above_low = order(plane_low, j_high);  // J_high - I_low
  if (above_low == Sign::uncertain) return false;
  if (above_low != Sign::negative) {
    const Sign below_high = order(plane_high, j_low);  // J_low - I_high
    if (below_high == Sign::uncertain) return false;
    if (below_high != Sign::positive) {
      // The segments meet: I_low <= J_high and J_low <= I_high. An end lies in the other
      // segment when it is not past the other's end on its own side.
      const Sign lows = order(plane_low, j_low);     // J_low - I_low
      const Sign highs = order(plane_high, j_high);  // J_high - I_high
      if (lows == Sign::uncertain || highs == Sign::uncertain) return false;
      low_i = lows != Sign::positive ? Answer::yes : Answer::no;
      high_i = highs != Sign::negative ? Answer::yes : Answer::no;
      low_j = lows != Sign::negative ? Answer::yes : Answer::no;
      high_j = highs != Sign::positive ? Answer::yes : Answer::no;
    }
  }
  // Edge k joins corners k and k + 1: f0-f1 is edge fl, f2-f0 edge fl + 2, f1-f2 misses.
  f_hits[fl] = i_low == 1 ? low_i : high_i;
  f_hits[(fl + 2) % 3] = i_low == 2 ? low_i : high_i;
  f_hits[(fl + 1) % 3] = Answer::no;
  x_hits[xl] = j_low == 1 ? low_j : high_j;
  x_hits[(xl + 2) % 3] = j_low == 2 ? low_j : high_j;
  x_hits[(xl + 1) % 3] = Answer::no;
  return true;
}

/// is_crossing with the sides of f's corners w.r.t. x's plane (sf) and of x's w.r.t. f's (sx)
/// computed here (see is_crossing_given_sides for callers that have them already).
template <class P>
SNAG_HD Answer is_crossing(const P& pred, const Tri& f, const Tri& x) {
  Sign sf[3], sx[3];
  corner_sides(pred, f, x, sf);
  corner_sides(pred, x, f, sx);
  return is_crossing_given_sides(pred, f, x, sf, sx);
}

}  // namespace snag::geom
