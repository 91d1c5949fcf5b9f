// A benchmark baseline only, never used by `snag check`: the plain floating-point
// triangle-triangle test most tools use (Moller, "A fast triangle-triangle intersection test",
// 1997: signed plane distances, the interval each triangle cuts on the planes' common line,
// and edge tests in a coordinate plane when coplanar), in doubles with no error bound and no
// tolerance. Shared vertices follow CGAL's rules (shared edge: coplanar and folded onto each
// other; shared vertex: an opposite edge meets the other triangle), evaluated the same way.
// `snag bench accuracy` measures how often this gets the answer wrong.
#pragma once

#include <optional>
#include <span>

#include "snag/detect/result.h"
#include "snag/geom/vec3.h"

namespace snag::cli::naive {

/// The kind of the pair when the floating-point test finds f and g intersecting (crossing when
/// each straddles the other's plane and their intervals overlap with positive length), or
/// nullopt when it finds them apart. Shared vertices are taken from the ids.
std::optional<detect::PairKind> intersect(std::span<const geom::Vec3d> positions,
                                          const geom::Tri& f, const geom::Tri& g);

/// Whether the triangle has zero area as computed in doubles (a zero cross product).
bool degenerate(std::span<const geom::Vec3d> positions, const geom::Tri& t);

}  // namespace snag::cli::naive
