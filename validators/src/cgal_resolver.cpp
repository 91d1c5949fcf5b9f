#include "snag/validators/cgal_resolver.h"

#include <string>

#include "cgal_predicates.h"
#include "snag/error.h"
#include "snag/geom/narrow_phase.h"

namespace snag::validators {

namespace {

bool decided(geom::Answer answer, const char* what) {
  if (answer == geom::Answer::uncertain)
    throw InternalError(std::string("exact predicates left a test undecided: ") + what);
  return answer == geom::Answer::yes;
}

class CgalResolver final : public detect::ExactResolver {
 public:
  void edge_hits(const detect::ExactContext& context,
                 std::span<const detect::EdgeTriangleTask> tasks, std::span<uint8_t> hit) override {
    const CgalPredicates pred{context.positions.data()};
    const detect::Topology& topo = *context.topology;
    const auto count = static_cast<int64_t>(tasks.size());
#pragma omp parallel for schedule(dynamic, 16) if (count > 256)
    for (int64_t i = 0; i < count; ++i) {
      const auto [p, q] = topo.edges[tasks[i].edge];
      const geom::Tri& t = topo.triangles[tasks[i].triangle];
      geom::Sign sp = geom::Sign::zero, sq = geom::Sign::zero;
      if (p != t.v[0] && p != t.v[1] && p != t.v[2]) sp = pred.orient3d(t.v[0], t.v[1], t.v[2], p);
      if (q != t.v[0] && q != t.v[1] && q != t.v[2]) sq = pred.orient3d(t.v[0], t.v[1], t.v[2], q);
      hit[i] = decided(geom::edge_hits_triangle(pred, p, q, t, sp, sq), "edge against triangle");
    }
  }

  void pair_kinds(const detect::ExactContext& context, std::span<const detect::FacePair> pairs,
                  std::span<detect::PairKind> kinds) override {
    const CgalPredicates pred{context.positions.data()};
    const detect::Topology& topo = *context.topology;
    const auto count = static_cast<int64_t>(pairs.size());
#pragma omp parallel for schedule(dynamic, 16) if (count > 256)
    for (int64_t i = 0; i < count; ++i) {
      const bool crossing =
          decided(geom::is_crossing(pred, topo.triangles[pairs[i].a], topo.triangles[pairs[i].b]),
                  "pair kind");
      kinds[i] = crossing ? detect::PairKind::crossing : detect::PairKind::touching;
    }
  }

  void degenerate(const detect::ExactContext& context, std::span<const int32_t> triangles,
                  std::span<uint8_t> degenerate) override {
    const CgalPredicates pred{context.positions.data()};
    const detect::Topology& topo = *context.topology;
    for (size_t i = 0; i < triangles.size(); ++i) {
      const geom::Tri& t = topo.triangles[triangles[i]];
      degenerate[i] = decided(geom::is_degenerate(pred, t.v[0], t.v[1], t.v[2]), "zero area");
    }
  }
};

}  // namespace

std::shared_ptr<detect::ExactResolver> make_cgal_resolver() {
  return std::make_shared<CgalResolver>();
}

}  // namespace snag::validators
