#include "snag/validators/exact_modes.h"

#include "snag/threads.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"

namespace snag::validators {

namespace {

class CgalConfirmer final : public detect::PairConfirmer {
 public:
  std::vector<detect::Disagreement> confirm(const detect::ExactContext& context,
                                            std::span<const detect::FacePair> pairs) override {
    const auto& triangles = context.topology->triangles;
    const auto count = static_cast<int64_t>(pairs.size());
    // 0: confirmed, 1: not intersecting, 2: the other kind.
    std::vector<uint8_t> verdict(pairs.size(), 0);
#pragma omp parallel for num_threads(thread_count(context.threads)) \
    schedule(dynamic, 64) if (count > 256)
    for (int64_t i = 0; i < count; ++i) {
      const geom::Tri& a = triangles[pairs[i].a];
      const geom::Tri& b = triangles[pairs[i].b];
      if (!cgal_faces_intersect(context.positions, a, b))
        verdict[i] = 1;
      else if (cgal_pair_kind(context.positions, a, b) != pairs[i].kind)
        verdict[i] = 2;
    }
    std::vector<detect::Disagreement> wrong;
    for (int64_t i = 0; i < count; ++i) {
      if (verdict[i] == 1) wrong.push_back({pairs[i], "CGAL finds no intersection"});
      if (verdict[i] == 2)
        wrong.push_back({pairs[i], pairs[i].kind == detect::PairKind::crossing
                                       ? "CGAL finds a touching pair"
                                       : "CGAL finds a crossing pair"});
    }
    return wrong;
  }
};

}  // namespace

std::shared_ptr<detect::PairConfirmer> make_cgal_confirmer() {
  return std::make_shared<CgalConfirmer>();
}

std::unique_ptr<detect::Checker> make_checker(std::unique_ptr<detect::Backend> backend,
                                              const detect::CheckSettings& settings) {
  std::shared_ptr<detect::ExactResolver> resolver;
  if (settings.exact != detect::ExactMode::off) resolver = make_cgal_resolver();
  std::shared_ptr<detect::PairConfirmer> confirmer;
  if (settings.exact == detect::ExactMode::all) confirmer = make_cgal_confirmer();
  return std::make_unique<detect::Checker>(std::move(backend), std::move(resolver), settings,
                                           std::move(confirmer));
}

}  // namespace snag::validators
