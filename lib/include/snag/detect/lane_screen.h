// The rejection by sides (pair_test.h: separated_by_sides) of a group's W pairs at once, for the
// CPU's group walks (bvh::LeafLanes): when the walk reaches a leaf x, every lane of the group
// that overlaps it and shares no vertex with it is a candidate pair (lane, x), and most such
// pairs end at that rejection. Pair by pair it cost about as much as the walk itself on
// cloth-ball (lib/NOTES.md); here the six sides of each of the W pairs are computed together
// (the lanes' corners against x's plane, x's corners against the lanes' planes), x's corners and
// plane loaded once, with no branch on a sign.
//
// The answer is separated_by_sides' bit for bit: the same roundings in the same order (no
// contraction: SNAG_STRICT_FP_FLAGS), the same certainty test, and a side the filter cannot
// certify counts as not separating, as it does there (plane_side_rare never answers a strict
// sign). Only pairs that share no vertex are screened: a shared corner's side is zero by topology.
// Host only.
#pragma once

#include <cstdint>

#include "snag/bvh/leaf_lanes.h"
#include "snag/detect/pair_test.h"
#include "snag/geom/predicates.h"

namespace snag::detect {

/// V doubles and V int64 as one vector each (explicit sizes, as bvh::LaneVectors).
template <int V>
struct DoubleVectors;
template <>
struct DoubleVectors<2> {
  typedef double Doubles __attribute__((vector_size(16)));
  typedef int64_t Longs __attribute__((vector_size(16)));
};
template <>
struct DoubleVectors<4> {
  typedef double Doubles __attribute__((vector_size(32)));
  typedef int64_t Longs __attribute__((vector_size(32)));
};

/// The lanes of a group (bvh::LeafLanes) as the rejection by sides reads them: each lane's
/// corners and its triangle's plane, one vector per coordinate and V lanes. V is 4 for groups
/// of 8 (one AVX instruction per operation: those groups run where the CPU has AVX2, see
/// cpu_backend.cpp) and 2 for groups of 4 (one SSE2 instruction, every x86-64 CPU), so that no
/// vector is wider than the instructions it is compiled for. Absent lanes hold zeros; they are
/// never wanted.
template <int W, int V = (W == 8 ? 4 : 2)>
class LaneScreen {
 public:
  static_assert(W == 4 || W == 8, "groups of 4 or 8 leaves");
  using Doubles = typename DoubleVectors<V>::Doubles;
  using Longs = typename DoubleVectors<V>::Longs;
  static constexpr int kPacks = W / V;
  static constexpr uint32_t kPackBits = (1u << V) - 1u;
  static constexpr int64_t kAllButSign = ~(int64_t{1} << 63);

  /// The lanes' triangles are base + lane_triangle[lane] for the first `members` lanes (a
  /// group's LeafLanes::triangle, local to its part); `triangles` and frame.planes are indexed
  /// by those ids.
  LaneScreen(const int32_t (&lane_triangle)[W], int members, const FrameView& frame,
             const geom::Tri* triangles, int32_t base) {
    for (int lane = 0; lane < W; ++lane) {
      const int q = lane / V, i = lane % V;
      const bool present = lane < members;
      const int32_t t = present ? base + lane_triangle[lane] : 0;
      for (int k = 0; k < 3; ++k) {
        const geom::Vec3d p = present ? frame.positions[triangles[t].v[k]] : geom::Vec3d{0, 0, 0};
        corner_[k][0][q][i] = p.x;
        corner_[k][1][q][i] = p.y;
        corner_[k][2][q][i] = p.z;
        minor_[q][k][i] = present ? frame.planes[t].minor[k] : 0.0;
        permanent_[q][k][i] = present ? frame.planes[t].permanent[k] : 0.0;
      }
    }
  }

  /// What the screen settles of a visit's pairs: bits of `wanted` only.
  struct Settled {
    /// separated_by_sides: the pair test would end with nothing to report.
    uint32_t separated = 0;
    /// Not separated, every side certain and nonzero, and straddling_edge_hits certain that the
    /// two segments where each triangle meets the other's plane are apart: the pair test would
    /// report a miss for every edge either triangle tests, and nothing else.
    uint32_t apart = 0;
  };

  /// The pairs of the lanes in `wanted` with triangle `xt` (plane `x_plane`), assuming each
  /// shares no vertex with it (callers mask out the lanes that do): the lanes' corners against
  /// x's plane first, then, for the lanes left, x's corners against the lanes' planes, then, for
  /// those still left, the two orientations of straddling_edge_hits that tell the segments apart.
  Settled settle(const geom::Vec3d* positions, const geom::PlaneCoefficients& x_plane,
                 const geom::Tri& xt, uint32_t wanted) const {
    Settled settled;
    // The lanes' corners against x's plane: rows corner - x0 (sides_against(t, x)).
    const geom::Vec3d x0 = positions[xt.v[0]];
    Longs t_above[kPacks][3], t_below[kPacks][3];
    for (int q = 0; q < kPacks; ++q) {
      if (((wanted >> (V * q)) & kPackBits) == 0) continue;
      for (int k = 0; k < 3; ++k) {
        const Doubles row[3] = {corner_[k][0][q] - x0.x, corner_[k][1][q] - x0.y,
                                corner_[k][2][q] - x0.z};
        side(row, x_plane.minor, x_plane.permanent, t_above[q][k], t_below[q][k]);
      }
      settled.separated |= alike_bits(t_above[q], t_below[q]) << (V * q);
    }
    settled.separated &= wanted;
    uint32_t left = wanted & ~settled.separated;
    if (left == 0) return settled;
    // x's corners against the lanes' planes: rows x_j - corner 0 (sides_against(x, t)).
    const geom::Vec3d x1 = positions[xt.v[1]], x2 = positions[xt.v[2]];
    const geom::Vec3d x_corner[3] = {x0, x1, x2};
    Longs x_above[kPacks][3], x_below[kPacks][3];
    for (int q = 0; q < kPacks; ++q) {
      if (((left >> (V * q)) & kPackBits) == 0) continue;
      for (int j = 0; j < 3; ++j) {
        const geom::Vec3d& d = x_corner[j];
        const Doubles row[3] = {d.x - corner_[0][0][q], d.y - corner_[0][1][q],
                                d.z - corner_[0][2][q]};
        side(row, minor_[q], permanent_[q], x_above[q][j], x_below[q][j]);
      }
      settled.separated |= alike_bits(x_above[q], x_below[q]) << (V * q);
    }
    settled.separated &= wanted;
    left = wanted & ~settled.separated;
    for (int q = 0; q < kPacks; ++q) {
      if (((left >> (V * q)) & kPackBits) == 0) continue;
      settled.apart |= apart_bits(q, x_corner, t_above[q], t_below[q], x_above[q], x_below[q])
                       << (V * q);
    }
    settled.apart &= left;
    return settled;
  }

 private:
  /// geom::row_side_filter for V rows at once, against one plane (coefficients: doubles) or V
  /// (Doubles): `above` / `below` set in the lanes whose sign the bound certifies positive /
  /// negative, neither where it is uncertain. (A scalar operand is taken in every lane.)
  template <class Coefficient>
  static void side(const Doubles (&row)[3], const Coefficient (&minor)[3],
                   const Coefficient (&permanent)[3], Longs& above, Longs& below) {
    const Doubles det = row[0] * minor[0] + row[1] * minor[1] + row[2] * minor[2];
    // |v| lane by lane: the sign bit cleared, as fabs does (a NaN stays a NaN).
    const Doubles abs_row[3] = {(Doubles)((Longs)row[0] & kAllButSign),
                                (Doubles)((Longs)row[1] & kAllButSign),
                                (Doubles)((Longs)row[2] & kAllButSign)};
    const Doubles abs_det = (Doubles)((Longs)det & kAllButSign);
    const Doubles perm =
        abs_row[0] * permanent[0] + abs_row[1] * permanent[1] + abs_row[2] * permanent[2];
    const Longs certain =
        (perm >= geom::detail::kMinPermanent) &
        (abs_det > geom::detail::kOrient3dBound * perm + geom::detail::kUnderflowSlack);
    above = certain & (det > 0.0);
    below = certain & (det < 0.0);
  }

  /// A bit per lane whose three corners lie certainly on one side: separated (no corner shared).
  static uint32_t alike_bits(const Longs (&above)[3], const Longs (&below)[3]) {
    return bvh::lane_bits((above[0] & above[1] & above[2]) | (below[0] & below[1] & below[2]));
  }

  /// A triangle's corners from its lone one on (fi or xj there), lane by lane: out[i] is
  /// corner (l + i) % 3 where lone[l] is set (exactly one of the three in the lanes that count).
  static void from_lone(const Longs (&lone)[3], const Doubles (&corner)[3], Doubles (&out)[3]) {
    for (int i = 0; i < 3; ++i)
      out[i] = (Doubles)((lone[0] & (Longs)corner[i]) | (lone[1] & (Longs)corner[(i + 1) % 3]) |
                         (lone[2] & (Longs)corner[(i + 2) % 3]));
  }

  /// `then` where `mask` is set, else `otherwise`, lane by lane, into `out`.
  static void choose(const Longs& mask, const Doubles& then, const Doubles& otherwise,
                     Doubles& out) {
    out = (Doubles)((mask & (Longs)then) | (~mask & (Longs)otherwise));
  }

  /// Lanes of pack q whose pair with x is straddling_edge_hits' "apart" case (see Settled),
  /// from the sides of both stages: each triangle's lone corner (the one whose side differs),
  /// then plane(f0, f_low, x0).side(x_high) and plane(f0, f_high, x0).side(x_low) with the same
  /// corners, roundings and sign conventions as there. A lane any of whose signs the filter
  /// cannot certify is not apart (the pair test decides it, with plane_side_rare).
  uint32_t apart_bits(int q, const geom::Vec3d (&x_corner)[3], const Longs (&t_above)[3],
                      const Longs (&t_below)[3], const Longs (&x_above)[3],
                      const Longs (&x_below)[3]) const {
    const Longs strict = (t_above[0] | t_below[0]) & (t_above[1] | t_below[1]) &
                         (t_above[2] | t_below[2]) & (x_above[0] | x_below[0]) &
                         (x_above[1] | x_below[1]) & (x_above[2] | x_below[2]);
    // With every side strict and not all alike, exactly one corner is lone: corner i when the
    // other two agree.
    const Longs t_lone[3] = {(t_above[1] & t_above[2]) | (t_below[1] & t_below[2]),
                             (t_above[0] & t_above[2]) | (t_below[0] & t_below[2]),
                             (t_above[0] & t_above[1]) | (t_below[0] & t_below[1])};
    const Longs x_lone[3] = {(x_above[1] & x_above[2]) | (x_below[1] & x_below[2]),
                             (x_above[0] & x_above[2]) | (x_below[0] & x_below[2]),
                             (x_above[0] & x_above[1]) | (x_below[0] & x_below[1])};
    // a > 0, b > 0: the lone corners' sides (sf[fl], sx[xl] there).
    const Longs a_positive =
        (t_lone[0] & t_above[0]) | (t_lone[1] & t_above[1]) | (t_lone[2] & t_above[2]);
    const Longs b_positive =
        (x_lone[0] & x_above[0]) | (x_lone[1] & x_above[1]) | (x_lone[2] & x_above[2]);
    const Longs flip = a_positive ^ b_positive;
    // fi = (f0, f(l+1), f(l+2)) and xj likewise, a coordinate at a time; then the ends: I2 < I1
    // when a > 0 (i_low = 2), J1 < J2 when b > 0 (j_low = 1).
    Doubles f0[3], f_low[3], f_high[3], x0[3], x_low[3], x_high[3];
    for (int axis = 0; axis < 3; ++axis) {
      const Doubles t_corner[3] = {corner_[0][axis][q], corner_[1][axis][q], corner_[2][axis][q]};
      // x's corners, each in every lane. (GCC 12 warns, wrongly, that these may be read
      // uninitialized once the walk is flattened: every lane is written here.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
      Doubles x_point[3];
      for (int k = 0; k < 3; ++k)
        for (int lane = 0; lane < V; ++lane) x_point[k][lane] = component(x_corner[k], axis);
#pragma GCC diagnostic pop
      Doubles fi[3], xj[3];
      from_lone(t_lone, t_corner, fi);
      from_lone(x_lone, x_point, xj);
      f0[axis] = fi[0];
      choose(a_positive, fi[2], fi[1], f_low[axis]);
      choose(a_positive, fi[1], fi[2], f_high[axis]);
      x0[axis] = xj[0];
      choose(b_positive, xj[1], xj[2], x_low[axis]);
      choose(b_positive, xj[2], xj[1], x_high[axis]);
    }
    // sign(J_high - I_low) and sign(J_low - I_high), each flipped when a b < 0.
    Longs low_above, low_below, high_above, high_below;
    orientation(f0, f_low, x0, x_high, low_above, low_below);
    orientation(f0, f_high, x0, x_low, high_above, high_below);
    const Longs above_low_negative = (flip & low_above) | (~flip & low_below);
    const Longs below_high_positive = (flip & high_below) | (~flip & high_above);
    // There: apart when J_high < I_low; else, once that sign is certain, when J_low > I_high.
    // Here only signs the filter certifies count: where plane_side_rare would find an exact
    // zero there (segments touching), the lane is left to the pair test.
    return bvh::lane_bits(strict &
                          (above_low_negative | ((low_above | low_below) & below_high_positive)));
  }

  /// plane_side_filter(PlaneCoefficients::of(a, b, c), a, d) lane by lane: `above` / `below`
  /// where the sign is certainly positive / negative. A row difference that might underflow in
  /// a product (not safe_difference) leaves the sign uncertain, as the NaN permanent does there.
  static void orientation(const Doubles (&a)[3], const Doubles (&b)[3], const Doubles (&c)[3],
                          const Doubles (&d)[3], Longs& above, Longs& below) {
    const Doubles u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const Doubles v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Doubles uyvz = u[1] * v[2], uzvy = u[2] * v[1], uzvx = u[2] * v[0], uxvz = u[0] * v[2],
                  uxvy = u[0] * v[1], uyvx = u[1] * v[0];
    const Doubles minor[3] = {uyvz - uzvy, uzvx - uxvz, uxvy - uyvx};
    const Doubles permanent[3] = {
        (Doubles)((Longs)uyvz & kAllButSign) + (Doubles)((Longs)uzvy & kAllButSign),
        (Doubles)((Longs)uzvx & kAllButSign) + (Doubles)((Longs)uxvz & kAllButSign),
        (Doubles)((Longs)uxvy & kAllButSign) + (Doubles)((Longs)uyvx & kAllButSign)};
    // geom::detail::safe_difference of each row component.
    Longs safe = ~Longs{};
    for (int k = 0; k < 3; ++k)
      for (const Doubles& difference : {u[k], v[k]})
        safe &= (difference == 0.0) |
                ((Doubles)((Longs)difference & kAllButSign) >= geom::detail::kMinDifference);
    const Doubles row[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    side(row, minor, permanent, above, below);
    above &= safe;
    below &= safe;
  }

  static double component(const geom::Vec3d& p, int axis) {
    return axis == 0 ? p.x : (axis == 1 ? p.y : p.z);
  }

  // 15 vectors of W doubles: 960 bytes for groups of 8, 480 for groups of 4, loaded once per
  // group that has a candidate.
  Doubles corner_[3][3][kPacks];  ///< [corner][axis][pack]: each lane's corner positions
  Doubles minor_[kPacks][3];      ///< [pack][k]: each lane's plane (geom::PlaneCoefficients)
  Doubles permanent_[kPacks][3];
};

}  // namespace snag::detect
