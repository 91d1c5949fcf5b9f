// The exact stage's three decisions over a predicate provider P that never answers uncertain
// (CGAL's exact predicates in validators/, RoundedPredicates for `--exact off`): the same
// decision procedures as the filter (snag/geom/narrow_phase.h), on the tests it left.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "snag/detect/exact.h"
#include "snag/error.h"
#include "snag/geom/narrow_phase.h"
#include "snag/threads.h"

namespace snag::detect {

namespace detail {
inline bool decided(geom::Answer answer, const char* what) {
  if (answer == geom::Answer::uncertain)
    throw InternalError(std::string("a predicate provider that is never uncertain left a test "
                                    "undecided: ") +
                        what);
  return answer == geom::Answer::yes;
}
}  // namespace detail

/// hit[i] = 1 when tasks[i]'s edge meets its triangle beyond their shared endpoints. Each of
/// the three loops here runs on thread_count(threads) threads (threads: ExactContext::threads).
template <class P>
void resolve_edge_hits(const P& pred, const Topology& topo, std::span<const EdgeTriangleTask> tasks,
                       std::span<uint8_t> hit, int threads) {
  const auto count = static_cast<int64_t>(tasks.size());
#pragma omp parallel for num_threads(thread_count(threads)) schedule(dynamic, 16) if (count > 256)
  for (int64_t i = 0; i < count; ++i) {
    const auto [p, q] = topo.edges[tasks[i].edge];
    const geom::Tri& t = topo.triangles[tasks[i].triangle];
    const bool p_shared = p == t.v[0] || p == t.v[1] || p == t.v[2];
    const bool q_shared = q == t.v[0] || q == t.v[1] || q == t.v[2];
    const geom::Sign sp = p_shared ? geom::Sign::zero : pred.orient3d(t.v[0], t.v[1], t.v[2], p);
    const geom::Sign sq = q_shared ? geom::Sign::zero : pred.orient3d(t.v[0], t.v[1], t.v[2], q);
    hit[i] =
        detail::decided(geom::edge_hits_triangle(pred, p, q, t, sp, sq), "edge against triangle");
  }
}

/// kinds[i] = the kind of the intersecting pair pairs[i].
template <class P>
void resolve_pair_kinds(const P& pred, const Topology& topo, std::span<const FacePair> pairs,
                        std::span<PairKind> kinds, int threads) {
  const auto count = static_cast<int64_t>(pairs.size());
#pragma omp parallel for num_threads(thread_count(threads)) schedule(dynamic, 16) if (count > 256)
  for (int64_t i = 0; i < count; ++i) {
    const bool crossing = detail::decided(
        geom::is_crossing(pred, topo.triangles[pairs[i].a], topo.triangles[pairs[i].b]),
        "pair kind");
    kinds[i] = crossing ? PairKind::crossing : PairKind::touching;
  }
}

/// degenerate[i] = 1 when triangles[i] has zero area (collinear corners).
template <class P>
void resolve_degenerate(const P& pred, const Topology& topo, std::span<const int32_t> triangles,
                        std::span<uint8_t> degenerate, int threads) {
  const auto count = static_cast<int64_t>(triangles.size());
#pragma omp parallel for num_threads(thread_count(threads)) schedule(static) if (count > 4096)
  for (int64_t i = 0; i < count; ++i) {
    const geom::Tri& t = topo.triangles[triangles[i]];
    degenerate[i] = detail::decided(geom::is_degenerate(pred, t.v[0], t.v[1], t.v[2]), "zero area");
  }
}

/// A resolver over a provider type: `Provider{positions}` per call.
template <class Provider>
class ProviderResolver : public ExactResolver {
 public:
  void edge_hits(const ExactContext& context, std::span<const EdgeTriangleTask> tasks,
                 std::span<uint8_t> hit) override {
    resolve_edge_hits(Provider{context.positions.data()}, *context.topology, tasks, hit,
                      context.threads);
  }
  void pair_kinds(const ExactContext& context, std::span<const FacePair> pairs,
                  std::span<PairKind> kinds) override {
    resolve_pair_kinds(Provider{context.positions.data()}, *context.topology, pairs, kinds,
                       context.threads);
  }
  void degenerate(const ExactContext& context, std::span<const int32_t> triangles,
                  std::span<uint8_t> degenerate) override {
    resolve_degenerate(Provider{context.positions.data()}, *context.topology, triangles, degenerate,
                       context.threads);
  }
};

/// `--exact off`: the filter's uncertain tests decided by the signs of the rounded doubles.
std::shared_ptr<ExactResolver> make_rounded_resolver();

}  // namespace snag::detect
