// expand_hits against a brute-force set of its pairs, at several thread counts, on random
// meshes with non-manifold edges and degenerate faces, large enough that every thread gets a
// share of the listing and of each radix pass; merge_pairs against a map of both its lists.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "snag/detect/pairs.h"
#include "snag/detect/topology.h"

namespace snag::detect {
namespace {

/// `count` proper triangles over `vertices` vertices: a strip of quads (every inner edge shared
/// by two faces), then random triangles, some of which reuse strip edges (three or more faces).
std::vector<geom::Tri> strip_and_soup(int32_t vertices, int32_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int32_t> vertex(0, vertices - 1);
  std::vector<geom::Tri> triangles;
  for (int32_t v = 0; v + 3 < vertices && static_cast<int32_t>(triangles.size()) < count / 2;
       v += 2) {
    triangles.push_back({{v, v + 1, v + 2}});
    triangles.push_back({{v + 1, v + 3, v + 2}});
  }
  while (static_cast<int32_t>(triangles.size()) < count) {
    const int32_t a = vertex(rng);
    geom::Tri t{{a, a + 1 < vertices ? a + 1 : a - 1, vertex(rng)}};
    if (t.v[2] == t.v[0] || t.v[2] == t.v[1]) continue;
    triangles.push_back(t);
  }
  return triangles;
}

TEST(ExpandHits, MatchesBruteForceAtEveryThreadCount) {
  for (const int32_t count : {50, 5000, 60000}) {
    const int32_t vertices = count / 2 + 3;
    const std::vector<geom::Tri> triangles = strip_and_soup(vertices, count, 7u + count);
    const Topology topo = make_topology(triangles, vertices);
    ASSERT_FALSE(topo.edges.empty());
    std::mt19937 rng(11u + count);
    std::vector<uint8_t> degenerate(triangles.size(), 0);
    for (size_t t = 0; t < degenerate.size(); t += 13) degenerate[t] = 1;
    std::uniform_int_distribution<int32_t> edge(0, static_cast<int32_t>(topo.edges.size()) - 1);
    std::uniform_int_distribution<int32_t> triangle(0, count - 1);
    // Hits with repeats (the same pair from several hits) and with the edge's own faces.
    std::vector<EdgeTriangleTask> hits;
    for (int32_t i = 0; i < 3 * count; ++i) {
      const int32_t e = edge(rng);
      const int32_t own = topo.edge_faces[topo.edge_face_offsets[e]];
      hits.push_back({e, i % 5 == 0 ? own : triangle(rng)});
      if (i % 7 == 0) hits.push_back(hits.back());
    }
    std::set<std::pair<int32_t, int32_t>> expected;
    for (const EdgeTriangleTask& hit : hits)
      for (int32_t i = topo.edge_face_offsets[hit.edge]; i < topo.edge_face_offsets[hit.edge + 1];
           ++i) {
        const int32_t face = topo.edge_faces[i];
        if (face != hit.triangle && !degenerate[face])
          expected.insert({std::min(face, hit.triangle), std::max(face, hit.triangle)});
      }
    auto expect_expected = [&](const std::vector<FacePair>& pairs) {
      ASSERT_EQ(pairs.size(), expected.size());
      auto want = expected.begin();
      for (const FacePair& pair : pairs) {
        EXPECT_EQ(std::make_pair(pair.a, pair.b), *want++);
        EXPECT_EQ(pair.kind, PairKind::touching);
      }
    };
    // 0: OpenMP's default count, as everywhere else.
    for (const int threads : {1, 2, 3, 8, 0}) {
      SCOPED_TRACE(testing::Message() << count << " triangles, " << threads << " threads");
      expect_expected(expand_hits(topo, hits, degenerate, threads));
    }
    // Inside a parallel region with no nesting allowed, the runtime gives a team of one where
    // expand_hits asks for eight: that one thread must take every run.
    SCOPED_TRACE(testing::Message() << count << " triangles, nested");
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(1);
    std::vector<FacePair> nested;
#pragma omp parallel num_threads(2)
    {
#pragma omp single
      nested = expand_hits(topo, hits, degenerate, 8);
    }
    omp_set_max_active_levels(levels);
    expect_expected(nested);
  }
}

TEST(ExpandHits, NoHitsNoPairs) {
  const std::vector<geom::Tri> triangles = {{{0, 1, 2}}, {{1, 3, 2}}};
  const Topology topo = make_topology(triangles, 4);
  const std::vector<uint8_t> degenerate(2, 0);
  EXPECT_TRUE(expand_hits(topo, {}, degenerate, 4).empty());
}

// merge_pairs against a std::map built from both lists, the first list's kind and flag winning
// on a pair both hold; and an empty second list leaving the first as it was.
TEST(MergePairs, MatchesAMapOfBothListsTheFirstWinning) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int32_t> id(0, 40);
  for (int round = 0; round < 200; ++round) {
    std::map<std::pair<int32_t, int32_t>, std::pair<PairKind, uint8_t>> lists[2];
    for (auto& list : lists) {
      const int count = static_cast<int>(rng() % 30);
      for (int i = 0; i < count; ++i) {
        int32_t a = id(rng), b = id(rng);
        if (a == b) continue;
        if (a > b) std::swap(a, b);
        list[{a, b}] = {rng() % 2 ? PairKind::crossing : PairKind::touching,
                        static_cast<uint8_t>(rng() % 2)};
      }
    }
    std::vector<FacePair> into, more;
    std::vector<uint8_t> into_flags, more_flags;
    for (const auto& [ids, value] : lists[0]) {
      into.push_back({ids.first, ids.second, value.first});
      into_flags.push_back(value.second);
    }
    for (const auto& [ids, value] : lists[1]) {
      more.push_back({ids.first, ids.second, value.first});
      more_flags.push_back(value.second);
    }
    auto expected = lists[1];
    for (const auto& [ids, value] : lists[0]) expected[ids] = value;
    merge_pairs(into, into_flags, more, more_flags);
    ASSERT_EQ(into.size(), expected.size());
    ASSERT_EQ(into_flags.size(), expected.size());
    size_t i = 0;
    for (const auto& [ids, value] : expected) {
      EXPECT_EQ(into[i], (FacePair{ids.first, ids.second, value.first}));
      EXPECT_EQ(into_flags[i], value.second);
      ++i;
    }
  }
}

}  // namespace
}  // namespace snag::detect
