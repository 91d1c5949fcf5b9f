// The exact predicate provider: the same interface as geom::FilteredPredicates, answered by
// CGAL's exact orientation predicates on the same double coordinates (never uncertain).
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "snag/geom/narrow_phase.h"
#include "snag/geom/predicates.h"

namespace snag::validators {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

inline geom::Sign to_sign(CGAL::Orientation o) {
  return o == CGAL::POSITIVE ? geom::Sign::positive
                             : (o == CGAL::NEGATIVE ? geom::Sign::negative : geom::Sign::zero);
}

struct CgalPredicates {
  const geom::Vec3d* positions;

  Kernel::Point_3 point(int32_t v) const {
    return {positions[v].x, positions[v].y, positions[v].z};
  }
  Kernel::Point_2 point(int32_t v, int axis) const {
    double u, w;
    geom::project(positions[v], axis, u, w);
    return {u, w};
  }
  /// CGAL::orientation(p, q, r, s) is the sign of det[q - p, r - p, s - p], as ours.
  geom::Sign orient3d(int32_t a, int32_t b, int32_t c, int32_t d) const {
    return to_sign(CGAL::orientation(point(a), point(b), point(c), point(d)));
  }
  geom::Sign orient2d(int32_t a, int32_t b, int32_t c, int axis) const {
    return to_sign(CGAL::orientation(point(a, axis), point(b, axis), point(c, axis)));
  }
  int dominant_axis(int32_t a, int32_t b, int32_t c) const {
    return geom::dominant_axis(positions[a], positions[b], positions[c]);
  }
  geom::OrientPlane<CgalPredicates> plane(int32_t a, int32_t b, int32_t c) const {
    return {this, a, b, c};
  }
};

}  // namespace snag::validators
