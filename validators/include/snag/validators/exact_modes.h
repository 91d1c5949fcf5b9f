// The checker for an `--exact` mode, wired with what that mode needs from CGAL: the exact
// resolver (`uncertain`, `all`) and the independent confirmation of every reported pair (`all`).
#pragma once

#include <memory>

#include "snag/detect/backend.h"
#include "snag/detect/checker.h"
#include "snag/detect/exact.h"

namespace snag::validators {

/// Confirms pairs with CGAL alone: that they intersect by CGAL's own rules
/// (cgal_faces_intersect: CGAL::do_intersect for pairs without shared vertices, CGAL's
/// shared-vertex and shared-edge rules otherwise), and their kind (cgal_pair_kind).
std::shared_ptr<detect::PairConfirmer> make_cgal_confirmer();

/// A checker for settings.exact on `backend`.
std::unique_ptr<detect::Checker> make_checker(std::unique_ptr<detect::Backend> backend,
                                              const detect::CheckSettings& settings);

}  // namespace snag::validators
