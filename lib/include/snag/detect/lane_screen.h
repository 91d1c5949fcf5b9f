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
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
        minor_[k][q][i] = present ? frame.planes[t].minor[k] : 0.0;
        permanent_[k][q][i] = present ? frame.planes[t].permanent[k] : 0.0;
      }
    }
  }

  /// A bit per lane of `wanted` whose pair with triangle `xt` (plane `x_plane`) is separated by
  /// sides, assuming the two share no vertex (callers mask out the lanes that do): every corner
  /// of one strictly on one side of the other's plane, certified by the filter. The lanes'
  /// corners against x's plane first; x's corners against the lanes' planes only for the lanes
  /// of `wanted` left. No bit outside `wanted` is set.
  uint32_t separated(const geom::Vec3d* positions, const geom::PlaneCoefficients& x_plane,
                     const geom::Tri& xt, uint32_t wanted) const {
    // The lanes' corners against x's plane: rows corner - x0 (sides_against(t, x)).
    const geom::Vec3d x0 = positions[xt.v[0]];
    uint32_t out = 0;
    for (int q = 0; q < kPacks; ++q) {
      if (((wanted >> (V * q)) & kPackBits) == 0) continue;
      Longs positive = ~Longs{}, negative = ~Longs{};
      for (int k = 0; k < 3; ++k) {
        const Doubles row[3] = {corner_[k][0][q] - x0.x, corner_[k][1][q] - x0.y,
                                corner_[k][2][q] - x0.z};
        side(row, x_plane.minor, x_plane.permanent, positive, negative);
      }
      out |= bits(positive | negative) << (V * q);
    }
    if ((wanted & ~out) == 0) return out & wanted;
    // x's corners against the lanes' planes: rows x_j - corner 0 (sides_against(x, t)).
    const geom::Vec3d x1 = positions[xt.v[1]], x2 = positions[xt.v[2]];
    const uint32_t left = wanted & ~out;
    for (int q = 0; q < kPacks; ++q) {
      if (((left >> (V * q)) & kPackBits) == 0) continue;
      Longs positive = ~Longs{}, negative = ~Longs{};
      const Doubles lane_minor[3] = {minor_[0][q], minor_[1][q], minor_[2][q]};
      const Doubles lane_permanent[3] = {permanent_[0][q], permanent_[1][q], permanent_[2][q]};
      for (const geom::Vec3d& d : {x0, x1, x2}) {
        const Doubles row[3] = {d.x - corner_[0][0][q], d.y - corner_[0][1][q],
                                d.z - corner_[0][2][q]};
        side(row, lane_minor, lane_permanent, positive, negative);
      }
      out |= bits(positive | negative) << (V * q);
    }
    return out & wanted;
  }

 private:
  /// geom::row_side_filter for V rows at once, against one plane (coefficients: doubles) or V
  /// (Doubles): `positive` / `negative` keep the lanes whose sign the bound certifies positive /
  /// negative; an uncertain lane drops from both. (A scalar operand is taken in every lane.
  /// Vectors by reference: a 32-byte vector in a call would have another ABI with AVX than
  /// without, as in bvh::LeafLanes.)
  template <class Coefficient>
  static void side(const Doubles (&row)[3], const Coefficient (&minor)[3],
                   const Coefficient (&permanent)[3], Longs& positive, Longs& negative) {
    // |v| lane by lane: the sign bits cleared, as fabs does (a NaN stays a NaN).
    constexpr int64_t kAllButSign = ~(int64_t{1} << 63);
    const Doubles det = row[0] * minor[0] + row[1] * minor[1] + row[2] * minor[2];
    const Doubles abs_row[3] = {(Doubles)((Longs)row[0] & kAllButSign),
                                (Doubles)((Longs)row[1] & kAllButSign),
                                (Doubles)((Longs)row[2] & kAllButSign)};
    const Doubles abs_det = (Doubles)((Longs)det & kAllButSign);
    const Doubles perm =
        abs_row[0] * permanent[0] + abs_row[1] * permanent[1] + abs_row[2] * permanent[2];
    const Longs certain =
        (perm >= geom::detail::kMinPermanent) &
        (abs_det > geom::detail::kOrient3dBound * perm + geom::detail::kUnderflowSlack);
    positive &= certain & (det > 0.0);
    negative &= certain & (det < 0.0);
  }

  /// Bit i set for each of the V lanes whose mask is all ones (two lanes a 16-byte piece).
  static uint32_t bits(const Longs& mask) {
    uint32_t out = 0;
#if defined(__SSE2__)
    for (int piece = 0; piece < V / 2; ++piece) {
      __m128d pair;
      std::memcpy(&pair, reinterpret_cast<const char*>(&mask) + 16 * piece, sizeof pair);
      out |= static_cast<uint32_t>(_mm_movemask_pd(pair)) << (2 * piece);
    }
#else
    for (int lane = 0; lane < V; ++lane) out |= static_cast<uint32_t>(mask[lane] & 1) << lane;
#endif
    return out;
  }

  // 15 vectors of W doubles: 960 bytes for groups of 8, 480 for groups of 4, loaded once per
  // group that has a candidate.
  Doubles corner_[3][3][kPacks];  ///< [corner][axis][pack]: each lane's corner positions
  Doubles minor_[3][kPacks];      ///< each lane's plane (geom::PlaneCoefficients)
  Doubles permanent_[3][kPacks];
};

}  // namespace snag::detect
