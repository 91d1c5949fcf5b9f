// Orientation predicates with a double-precision filter whose error bound is proven
// (Shewchuk, "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates", 1997: the bounds ccwerrboundA and o3derrboundA). A sign the bound cannot
// certify is `uncertain` and must be decided exactly (validators/: CGAL); no epsilon anywhere.
//
// Conventions: orient3d(a, b, c, d) is the sign of det[b - a, c - a, d - a], positive when d
// lies on the side that (b - a) x (c - a) points to; orient2d(a, b, c) is the sign of
// det[b - a, c - a] in a coordinate plane, positive when a, b, c turn counterclockwise.
//
// The bounds assume every operation is rounded on its own (no fused multiply-add: the build
// passes -ffp-contract=off / -fmad=false) and that nothing underflows; inputs whose permanent
// is tiny enough for underflow to matter, or that overflow, come out uncertain.
#pragma once

#include <cmath>
#include <cstdint>

#include "snag/geom/hd.h"
#include "snag/geom/vec3.h"

namespace snag::geom {

enum class Sign : int8_t { negative = -1, zero = 0, positive = 1, uncertain = 2 };

SNAG_HD_INLINE Sign negate(Sign s) {
  return s == Sign::positive ? Sign::negative : (s == Sign::negative ? Sign::positive : s);
}

namespace detail {
// 2^-53: half a unit in the last place of 1.
constexpr double kEpsilon = 1.1102230246251565e-16;
constexpr double kOrient2dBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
// Below this permanent, products may have underflowed and the relative bound no longer holds.
constexpr double kMinPermanent = 0x1p-900;
// About twenty times the largest error (3 * 2^-1075) that underflow in the three final products
// of a query can add to its determinant and its permanent. With a permanent of at least
// kMinPermanent the bound kOrient3dBound * perm is at least 2^-951, so this term rounds away in
// the sum; what covers the underflow there is that det and the rounded bound are both doubles:
// |det| > bound means |det| >= bound + ulp(bound) >= bound + 2^-1003, far more than 2^-1073.
// (An error up to `bound` is what the relative bound covers without underflow; the products
// of the plane's coefficients cannot underflow, see PlaneCoefficients::of; the three products
// of the query row can, each by at most 2^-1075 in the determinant and in the permanent, and
// sums whose result is subnormal are exact.) The term is kept for bounds that do not round it
// away, and it only ever makes the filter more cautious.
constexpr double kUnderflowSlack = 0x1p-1069;
// A difference this large or exactly zero keeps every product of three of them normal.
constexpr double kMinDifference = 0x1p-300;

SNAG_HD_INLINE bool safe_difference(double d) {
  return d == 0.0 || fabs(d) >= kMinDifference;
}

SNAG_HD_INLINE Sign sign_of(double det) {
  return det > 0 ? Sign::positive : Sign::negative;
}
}  // namespace detail

/// Sign of det[(ax - cx, ay - cy), (bx - cx, by - cy)] for 2D points given by coordinates.
SNAG_HD_INLINE Sign orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double acx = ax - cx, bcx = bx - cx, acy = ay - cy, bcy = by - cy;
  const double left = acx * bcy, right = acy * bcx;
  const double det = left - right;
  const double permanent = fabs(left) + fabs(right);
  // A product that underflowed is off by at most 2^-1075: covered, as in orient3d, by the
  // strict comparison of two doubles (see kUnderflowSlack).
  if (permanent >= detail::kMinPermanent && fabs(det) > detail::kOrient2dBound * permanent)
    return detail::sign_of(det);
  // Both products exactly zero because a difference is exactly zero: the determinant is zero.
  if ((acx == 0.0 || bcy == 0.0) && (acy == 0.0 || bcx == 0.0)) return Sign::zero;
  // a == b: the determinant is zero, though its rounded products need not be (acx * acy -
  // acy * acx). (a == c or b == c makes a difference exactly zero, caught above.) So a triangle
  // with two coincident corners, whose leaf box is empty (bvh::leaf_box), is certainly
  // degenerate in the scan on both backends.
  if (ax == bx && ay == by) return Sign::zero;
  return Sign::uncertain;
}

/// The two coordinates kept when projecting along `axis`, in cyclic order (axis 0 keeps y, z;
/// 1 keeps z, x; 2 keeps x, y), so that orient2d of a projected triangle has the sign of its
/// normal's `axis` component.
SNAG_HD_INLINE void project(Vec3d p, int axis, double& u, double& v) {
  if (axis == 0) {
    u = p.y;
    v = p.z;
  } else if (axis == 1) {
    u = p.z;
    v = p.x;
  } else {
    u = p.x;
    v = p.y;
  }
}

SNAG_HD_INLINE Sign orient2d(Vec3d a, Vec3d b, Vec3d c, int axis) {
  double au, av, bu, bv, cu, cv;
  project(a, axis, au, av);
  project(b, axis, bu, bv);
  project(c, axis, cu, cv);
  return orient2d(au, av, bu, bv, cu, cv);
}

/// orient3d(a, b, c, .) for a fixed plane through a, b, c: the plane's part of the determinant
/// is computed once (per frame, for every triangle), each query point then costs three
/// differences, six products and a bound (48 bytes per plane).
///
/// det[u, v, w] with u = b - a, v = c - a, w = d - a is w . (u x v): every entry of the 3x3
/// matrix is a difference of two inputs, the 2x2 minors come from two rows and multiply the
/// third, which is exactly the form of Shewchuk's orient3d (his rows are a - d, b - d, c - d),
/// so his bound o3derrboundA times the permanent sum_k |w_k| (|u_i v_j| + |u_j v_i|) holds.
struct PlaneCoefficients {
  double minor[3];  ///< (u x v)_k, each rounded
  /// |u_i v_j| + |u_j v_i| for the same k; NaN when a difference of u or v is nonzero but so
  /// small that a product may underflow, which makes every query through the plane uncertain
  /// (an underflowed minor times a large w_k can exceed any relative bound).
  double permanent[3];

  SNAG_HD_INLINE static PlaneCoefficients of(Vec3d a, Vec3d b, Vec3d c) {
    return of_rows(b - a, c - a);
  }

  /// The coefficients of det[u, v, .] for rows given as vectors, each component exact or one
  /// rounded difference of inputs (of(a, b, c) is of_rows(b - a, c - a)); the bound holds as for
  /// of(), rows with fewer roundings only tightening it.
  SNAG_HD_INLINE static PlaneCoefficients of_rows(Vec3d u, Vec3d v) {
    const double ux = u.x, uy = u.y, uz = u.z;
    const double vx = v.x, vy = v.y, vz = v.z;
    const double uyvz = uy * vz, uzvy = uz * vy, uzvx = uz * vx, uxvz = ux * vz, uxvy = ux * vy,
                 uyvx = uy * vx;
    PlaneCoefficients k{
        {uyvz - uzvy, uzvx - uxvz, uxvy - uyvx},
        {fabs(uyvz) + fabs(uzvy), fabs(uzvx) + fabs(uxvz), fabs(uxvy) + fabs(uyvx)}};
    using detail::safe_difference;
    if (!(safe_difference(ux) && safe_difference(uy) && safe_difference(uz) &&
          safe_difference(vx) && safe_difference(vy) && safe_difference(vz)))
      k.permanent[0] = NAN;
    return k;
  }
};

namespace detail {
/// The uncertain path: exact zeros the bound cannot show. A point equal to a corner repeats a
/// row of the matrix (unwelded seams do this often); a vanished permanent is an exact zero
/// unless a product underflowed to zero.
SNAG_HD inline Sign plane_side_rare(Vec3d a, Vec3d b, Vec3d c, Vec3d d, double perm) {
  if (d == a || d == b || d == c) return Sign::zero;
  if (perm == 0.0 && safe_difference(d.x - a.x) && safe_difference(d.y - a.y) &&
      safe_difference(d.z - a.z) && safe_difference(b.x - a.x) && safe_difference(b.y - a.y) &&
      safe_difference(b.z - a.z) && safe_difference(c.x - a.x) && safe_difference(c.y - a.y) &&
      safe_difference(c.z - a.z))
    return Sign::zero;
  return Sign::uncertain;
}
}  // namespace detail

/// The filter's sign of det[u, v, w] for k = PlaneCoefficients::of_rows(u, v) and a third row
/// `w` whose components are exact or one rounded difference each, else Sign::uncertain; `perm`
/// receives the permanent.
SNAG_HD_INLINE Sign row_side_filter(const PlaneCoefficients& k, Vec3d w, double& perm) {
  const double det = w.x * k.minor[0] + w.y * k.minor[1] + w.z * k.minor[2];
  perm = fabs(w.x) * k.permanent[0] + fabs(w.y) * k.permanent[1] + fabs(w.z) * k.permanent[2];
  if (perm >= detail::kMinPermanent &&
      fabs(det) > detail::kOrient3dBound * perm + detail::kUnderflowSlack)
    return detail::sign_of(det);
  return Sign::uncertain;
}

/// The filter part of plane_side: the sign of det[b - a, c - a, d - a] when the bound certifies
/// it, else Sign::uncertain; `perm` receives the permanent for plane_side_rare. The plane's
/// products cannot underflow (PlaneCoefficients::of makes such a plane's queries uncertain);
/// the query's three products w_k * minor_k can, by at most 2^-1075 each, which the absolute
/// term kUnderflowSlack covers.
SNAG_HD_INLINE Sign plane_side_filter(const PlaneCoefficients& k, Vec3d a, Vec3d d, double& perm) {
  return row_side_filter(k, d - a, perm);
}

/// Sign of det[b - a, c - a, d - a] from the plane's coefficients (k = PlaneCoefficients::of(a, b,
/// c)).
SNAG_HD_INLINE Sign plane_side(const PlaneCoefficients& k, Vec3d a, Vec3d b, Vec3d c, Vec3d d) {
  double perm;
  const Sign sign = plane_side_filter(k, a, d, perm);
  return sign != Sign::uncertain ? sign : detail::plane_side_rare(a, b, c, d, perm);
}

/// Sign of det[b - a, c - a, d - a]; bit for bit what plane_side answers.
SNAG_HD_INLINE Sign orient3d(Vec3d a, Vec3d b, Vec3d c, Vec3d d) {
  return plane_side(PlaneCoefficients::of(a, b, c), a, b, c, d);
}

/// The axis along which a triangle's normal has its largest component (as computed in
/// doubles); projecting along it keeps the triangle as large as possible, which makes the
/// filter succeed most often. Any axis with a nonzero exact component is correct.
SNAG_HD_INLINE int dominant_axis(Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d n = cross(b - a, c - a);
  const double x = fabs(n.x), y = fabs(n.y), z = fabs(n.z);
  return (x >= y && x >= z) ? 0 : (y >= z ? 1 : 2);
}

/// The predicate provider of the filtered path: vertex ids into one frame's positions.
/// The exact provider (validators/) has the same interface and never answers `uncertain`.
struct FilteredPredicates {
  const Vec3d* positions;

  SNAG_HD_INLINE Sign orient3d(int32_t a, int32_t b, int32_t c, int32_t d) const {
    return geom::orient3d(positions[a], positions[b], positions[c], positions[d]);
  }
  SNAG_HD_INLINE Sign orient2d(int32_t a, int32_t b, int32_t c, int axis) const {
    return geom::orient2d(positions[a], positions[b], positions[c], axis);
  }
  SNAG_HD_INLINE int dominant_axis(int32_t a, int32_t b, int32_t c) const {
    return geom::dominant_axis(positions[a], positions[b], positions[c]);
  }
  /// The plane through a, b, c, asked about many points: plane(a, b, c).side(d) ==
  /// orient3d(a, b, c, d).
  struct Plane {
    PlaneCoefficients k;
    Vec3d a, b, c;
    const Vec3d* positions;
    SNAG_HD_INLINE Sign side(int32_t d) const { return plane_side(k, a, b, c, positions[d]); }
  };
  SNAG_HD_INLINE Plane plane(int32_t a, int32_t b, int32_t c) const {
    const Vec3d pa = positions[a], pb = positions[b], pc = positions[c];
    return {PlaneCoefficients::of(pa, pb, pc), pa, pb, pc, positions};
  }
};

/// The signs of the plain double evaluation with no error bound, zero only when the rounded
/// determinant is zero: what `--exact off` decides the filter's uncertain tests with. The same
/// expressions as the filter (plane_side, orient2d), so where the filter is certain both agree;
/// where it is not, the sign may be wrong (a near-degenerate configuration, or an exact zero
/// that rounds to a tiny nonzero value). Never answers `uncertain`.
struct RoundedPredicates {
  const Vec3d* positions;

  SNAG_HD_INLINE static Sign sign_of(double det) {
    return det > 0 ? Sign::positive : (det < 0 ? Sign::negative : Sign::zero);
  }
  SNAG_HD_INLINE Sign orient3d(int32_t a, int32_t b, int32_t c, int32_t d) const {
    const Vec3d pa = positions[a], pd = positions[d];
    const PlaneCoefficients k = PlaneCoefficients::of(pa, positions[b], positions[c]);
    return sign_of((pd.x - pa.x) * k.minor[0] + (pd.y - pa.y) * k.minor[1] +
                   (pd.z - pa.z) * k.minor[2]);
  }
  SNAG_HD_INLINE Sign orient2d(int32_t a, int32_t b, int32_t c, int axis) const {
    double au, av, bu, bv, cu, cv;
    project(positions[a], axis, au, av);
    project(positions[b], axis, bu, bv);
    project(positions[c], axis, cu, cv);
    return sign_of((au - cu) * (bv - cv) - (av - cv) * (bu - cu));
  }
  SNAG_HD_INLINE int dominant_axis(int32_t a, int32_t b, int32_t c) const {
    return geom::dominant_axis(positions[a], positions[b], positions[c]);
  }
  struct Plane {
    const RoundedPredicates* pred;
    int32_t a, b, c;
    SNAG_HD_INLINE Sign side(int32_t d) const { return pred->orient3d(a, b, c, d); }
  };
  SNAG_HD_INLINE Plane plane(int32_t a, int32_t b, int32_t c) const { return {this, a, b, c}; }
};

}  // namespace snag::geom
