// Decides, with CGAL's exact predicates, the tests snag's double filter could not certify.
// It runs the same decision procedures as the filter (snag/geom/narrow_phase.h), with CGAL's
// exact orientation predicates as the predicate provider.
#pragma once

#include <memory>

#include "snag/detect/exact.h"

namespace snag::validators {

std::shared_ptr<detect::ExactResolver> make_cgal_resolver();

}  // namespace snag::validators
