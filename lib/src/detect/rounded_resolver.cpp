#include "snag/detect/resolve.h"
#include "snag/geom/predicates.h"

namespace snag::detect {

std::shared_ptr<ExactResolver> make_rounded_resolver() {
  return std::make_shared<ProviderResolver<geom::RoundedPredicates>>();
}

}  // namespace snag::detect
