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
// A difference this large or exactly zero keeps every product of three of them normal.
constexpr double kMinDifference = 0x1p-300;

SNAG_HD_INLINE bool safe_difference(double d) { return d == 0.0 || fabs(d) >= kMinDifference; }

SNAG_HD_INLINE Sign sign_of(double det) { return det > 0 ? Sign::positive : Sign::negative; }
}  // namespace detail

/// Sign of det[(ax - cx, ay - cy), (bx - cx, by - cy)] for 2D points given by coordinates.
SNAG_HD_INLINE Sign orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double acx = ax - cx, bcx = bx - cx, acy = ay - cy, bcy = by - cy;
  const double left = acx * bcy, right = acy * bcx;
  const double det = left - right;
  const double permanent = fabs(left) + fabs(right);
  if (permanent >= detail::kMinPermanent && fabs(det) > detail::kOrient2dBound * permanent)
    return detail::sign_of(det);
  // Both products exactly zero because a difference is exactly zero: the determinant is zero.
  if ((acx == 0.0 || bcy == 0.0) && (acy == 0.0 || bcx == 0.0)) return Sign::zero;
  return Sign::uncertain;
}

/// The two coordinates kept when projecting along `axis`, in cyclic order (axis 0 keeps y, z;
/// 1 keeps z, x; 2 keeps x, y), so that orient2d of a projected triangle has the sign of its
/// normal's `axis` component.
SNAG_HD_INLINE void project(Vec3d p, int axis, double& u, double& v) {
  if (axis == 0) { u = p.y; v = p.z; }
  else if (axis == 1) { u = p.z; v = p.x; }
  else { u = p.x; v = p.y; }
}

SNAG_HD_INLINE Sign orient2d(Vec3d a, Vec3d b, Vec3d c, int axis) {
  double au, av, bu, bv, cu, cv;
  project(a, axis, au, av);
  project(b, axis, bu, bv);
  project(c, axis, cu, cv);
  return orient2d(au, av, bu, bv, cu, cv);
}

/// Sign of det[b - a, c - a, d - a].
SNAG_HD_INLINE Sign orient3d(Vec3d a, Vec3d b, Vec3d c, Vec3d d) {
  // Shewchuk's arrangement: differences to d, then 2x2 minors; his determinant is the
  // negation of ours.
  const double adx = a.x - d.x, bdx = b.x - d.x, cdx = c.x - d.x;
  const double ady = a.y - d.y, bdy = b.y - d.y, cdy = c.y - d.y;
  const double adz = a.z - d.z, bdz = b.z - d.z, cdz = c.z - d.z;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (fabs(bdxcdy) + fabs(cdxbdy)) * fabs(adz) + (fabs(cdxady) + fabs(adxcdy)) * fabs(bdz) +
                           (fabs(adxbdy) + fabs(bdxady)) * fabs(cdz);
  if (permanent >= detail::kMinPermanent && fabs(det) > detail::kOrient3dBound * permanent)
    return negate(detail::sign_of(det));
  if (permanent == 0.0) {
    // Every term vanished; it is an exact zero unless a product underflowed to zero.
    using detail::safe_difference;
    if (safe_difference(adx) && safe_difference(bdx) && safe_difference(cdx) && safe_difference(ady) &&
        safe_difference(bdy) && safe_difference(cdy) && safe_difference(adz) && safe_difference(bdz) &&
        safe_difference(cdz))
      return Sign::zero;
  }
  return Sign::uncertain;
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
};

}  // namespace snag::geom
