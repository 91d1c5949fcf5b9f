// The exact stage's loops (detect/resolve.h): each answer is its provider's decision for that
// item, and the loops run on the threads the context gives (snag check's --threads), not on
// every core.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <random>
#include <vector>

#include "detect_cases.h"
#include "snag/detect/resolve.h"
#include "snag/detect/topology.h"
#include "snag/geom/predicates.h"

namespace snag::detect {
namespace {

using test::random_soup;
using test::SmallMesh;

/// The most threads of any team a CountingPredicates was called from.
std::atomic<int> most_threads{0};

void note_team() {
  const int team = omp_get_num_threads();
  int seen = most_threads.load();
  while (team > seen && !most_threads.compare_exchange_weak(seen, team)) {
  }
}

/// RoundedPredicates (never uncertain) that note the team they are called from.
struct CountingPredicates {
  const geom::Vec3d* positions;

  geom::Sign orient3d(int32_t a, int32_t b, int32_t c, int32_t d) const {
    note_team();
    return geom::RoundedPredicates{positions}.orient3d(a, b, c, d);
  }
  geom::Sign orient2d(int32_t a, int32_t b, int32_t c, int axis) const {
    note_team();
    return geom::RoundedPredicates{positions}.orient2d(a, b, c, axis);
  }
  int dominant_axis(int32_t a, int32_t b, int32_t c) const {
    return geom::RoundedPredicates{positions}.dominant_axis(a, b, c);
  }
  geom::OrientPlane<CountingPredicates> plane(int32_t a, int32_t b, int32_t c) const {
    return {this, a, b, c};
  }
};

TEST(Resolve, LoopsRunOnTheContextsThreadsAndGiveTheProvidersAnswers) {
  const int cores = omp_get_max_threads();
  // Corners spread far beyond the 10-unit cube of the centres: triangles as large as the
  // region, so that the arbitrary pairs below often meet (186 of the 2,000 edge tests hit and
  // 552 pairs are crossings, as many as corners anywhere in a cube gave; with small triangles
  // every answer would be `no`).
  const SmallMesh soup = random_soup(6000, 11, 50.0);
  const Topology topology =
      make_topology(soup.triangles, static_cast<int32_t>(soup.positions.size()));
  const geom::RoundedPredicates rounded{soup.positions.data()};
  // Enough items for every loop to go parallel (more than 256 tests or pairs, 4,096 triangles).
  std::vector<EdgeTriangleTask> tasks;
  std::vector<FacePair> pairs;
  for (int32_t i = 0; i < 2000; ++i) {
    const int32_t t = i % 3000, x = 3000 + (i * 7) % 3000;
    tasks.push_back({topology.triangle_edges[t][i % 3], x});
    pairs.push_back({t, x, PairKind::touching});
  }
  std::vector<int32_t> triangles(soup.triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) triangles[t] = static_cast<int32_t>(t);

  for (int threads : {1, 2, 3}) {
    SCOPED_TRACE("threads=" + std::to_string(threads) + " cores=" + std::to_string(cores));
    ProviderResolver<CountingPredicates> resolver;
    const ExactContext context{soup.positions, &topology, threads};
    std::vector<uint8_t> hit(tasks.size()), degenerate(triangles.size());
    std::vector<PairKind> kinds(pairs.size());
    most_threads = 0;
    resolver.edge_hits(context, tasks, hit);
    resolver.pair_kinds(context, pairs, kinds);
    resolver.degenerate(context, triangles, degenerate);
    EXPECT_GE(most_threads.load(), 1);
    EXPECT_LE(most_threads.load(), threads);
    for (size_t i = 0; i < tasks.size(); ++i) {
      const auto [p, q] = topology.edges[tasks[i].edge];
      const geom::Tri& t = topology.triangles[tasks[i].triangle];
      const geom::Answer expected =
          geom::edge_hits_triangle(rounded, p, q, t, rounded.orient3d(t.v[0], t.v[1], t.v[2], p),
                                   rounded.orient3d(t.v[0], t.v[1], t.v[2], q));
      ASSERT_EQ(hit[i], expected == geom::Answer::yes) << "task " << i;
    }
    for (size_t i = 0; i < pairs.size(); ++i) {
      const geom::Answer crossing = geom::is_crossing(rounded, topology.triangles[pairs[i].a],
                                                      topology.triangles[pairs[i].b]);
      ASSERT_EQ(kinds[i] == PairKind::crossing, crossing == geom::Answer::yes) << "pair " << i;
    }
    EXPECT_GT(std::count(hit.begin(), hit.end(), 1), 0);  // the answers are not all `no`
    EXPECT_GT(std::count(kinds.begin(), kinds.end(), PairKind::crossing), 0);
    EXPECT_EQ(std::count(degenerate.begin(), degenerate.end(), 1), 0);
  }
  // Without a thread count (0), OpenMP's default: every core may take part.
  if (cores > 1) {
    ProviderResolver<CountingPredicates> resolver;
    std::vector<PairKind> kinds(pairs.size());
    most_threads = 0;
    resolver.pair_kinds({soup.positions, &topology, 0}, pairs, kinds);
    EXPECT_EQ(most_threads.load(), cores);
  }
}

}  // namespace
}  // namespace snag::detect
