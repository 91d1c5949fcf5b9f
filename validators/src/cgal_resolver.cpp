#include "snag/validators/cgal_resolver.h"

#include "cgal_predicates.h"
#include "snag/detect/resolve.h"

namespace snag::validators {

std::shared_ptr<detect::ExactResolver> make_cgal_resolver() {
  return std::make_shared<detect::ProviderResolver<CgalPredicates>>();
}

}  // namespace snag::validators
