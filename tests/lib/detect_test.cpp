// The whole CPU path against a brute-force O(n^2) reference, on random soups and meshes of
// small integer coordinates (full of exact contacts), for several thread counts; refit
// against rebuild.
#include <gtest/gtest.h>

#include <random>

#include "detect_fixture.h"

namespace snag::test {
namespace {

/// Every pair of non-degenerate triangles, decided straight from the definition (an edge of
/// either meets the other beyond their shared endpoints; a duplicated face always), with the
/// exact integer predicates: no tree, no representative triangles, no filter.
std::vector<detect::FacePair> brute_force(const SmallMesh& mesh) {
  const IntegerPredicates pred{mesh.positions.data()};
  const auto n = static_cast<int32_t>(mesh.triangles.size());
  std::vector<uint8_t> degenerate(static_cast<size_t>(n));
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri& tri = mesh.triangles[t];
    degenerate[t] = IntegerResolver::decide(geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]));
  }
  auto edge_hits = [&](const geom::Tri& f, const geom::Tri& x) {
    for (int k = 0; k < 3; ++k) {
      const int32_t p = f.v[k], q = f.v[(k + 1) % 3];
      const bool p_in = p == x.v[0] || p == x.v[1] || p == x.v[2], q_in = q == x.v[0] || q == x.v[1] || q == x.v[2];
      if (p_in && q_in) continue;
      if (IntegerResolver::decide(geom::edge_hits_triangle(pred, p, q, x, IntegerResolver::side(pred, x, p),
                                                           IntegerResolver::side(pred, x, q))))
        return true;
    }
    return false;
  };
  std::vector<detect::FacePair> pairs;
  for (int32_t a = 0; a < n; ++a) {
    if (degenerate[a]) continue;
    for (int32_t b = a + 1; b < n; ++b) {
      if (degenerate[b]) continue;
      const geom::Tri &fa = mesh.triangles[a], &fb = mesh.triangles[b];
      int shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) shared += fa.v[i] == fb.v[j];
      if (shared == 3 || edge_hits(fa, fb) || edge_hits(fb, fa)) {
        const bool crossing = IntegerResolver::decide(geom::is_crossing(pred, fa, fb));
        pairs.push_back({a, b, crossing ? detect::PairKind::crossing : detect::PairKind::touching});
      }
    }
  }
  return pairs;
}

/// A triangle soup on a coarse integer lattice: coincident vertices, coplanar and collinear
/// configurations, shared ids (a vertex pool smaller than 3n) and zero-area faces all occur.
SmallMesh lattice_soup(int32_t triangles, int32_t vertices, int range, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(0, range);
  std::uniform_int_distribution<int32_t> pick(0, vertices - 1);
  SmallMesh mesh;
  for (int32_t v = 0; v < vertices; ++v) mesh.positions.push_back({double(coord(rng)), double(coord(rng)), double(coord(rng))});
  for (int32_t t = 0; t < triangles; ++t) mesh.triangles.push_back({{pick(rng), pick(rng), pick(rng)}});
  return mesh;
}

/// A folded grid: a w x h sheet whose rows bend back through the sheet, in integer coordinates.
SmallMesh folded_grid(int w, int h) {
  SmallMesh mesh;
  for (int j = 0; j <= h; ++j)
    for (int i = 0; i <= w; ++i) {
      const int fold = (i * 3) % (2 * w);  // zig-zag in x: the sheet passes through itself
      mesh.positions.push_back({double(fold < w ? fold : 2 * w - fold), double(j * 2), double((i * i) % 7)});
    }
  auto id = [&](int i, int j) { return j * (w + 1) + i; };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      mesh.triangles.push_back({{id(i, j), id(i + 1, j), id(i + 1, j + 1)}});
      mesh.triangles.push_back({{id(i, j), id(i + 1, j + 1), id(i, j + 1)}});
    }
  return mesh;
}

TEST(Detect, MatchesBruteForceOnLatticeSoups) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const int32_t n = 20 + static_cast<int32_t>(seed * 7 % 90);
    const SmallMesh mesh = lattice_soup(n, n + static_cast<int32_t>(seed % 3) * n, 3 + static_cast<int>(seed % 5), seed);
    const std::vector<detect::FacePair> expected = brute_force(mesh);
    for (int threads : {1, 2, 3}) {
      const detect::FrameResult result = check_mesh(mesh, threads);
      ASSERT_EQ(result.pairs, expected) << "seed " << seed << " threads " << threads;
    }
  }
}

TEST(Detect, MatchesBruteForceOnFoldedGrids) {
  for (auto [w, h] : {std::pair{6, 4}, std::pair{11, 7}, std::pair{17, 9}}) {
    const SmallMesh mesh = folded_grid(w, h);
    const std::vector<detect::FacePair> expected = brute_force(mesh);
    ASSERT_FALSE(expected.empty());
    EXPECT_EQ(check_mesh(mesh, 2).pairs, expected) << w << "x" << h;
  }
}

TEST(Detect, RefitMatchesRebuildAndBruteForceAfterDeformation) {
  SmallMesh mesh = folded_grid(15, 10);
  auto resolver = std::make_shared<IntegerResolver>();
  detect::Checker refitting(detect::make_cpu_backend(2), resolver, {detect::RebuildPolicy::never});
  detect::Checker rebuilding(detect::make_cpu_backend(2), resolver, {detect::RebuildPolicy::always});
  refitting.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  rebuilding.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> step(-2, 2);
  for (int frame = 0; frame < 6; ++frame) {
    const detect::FrameResult a = refitting.check(mesh.positions);
    const detect::FrameResult b = rebuilding.check(mesh.positions);
    EXPECT_EQ(a.pairs, b.pairs) << "frame " << frame;
    EXPECT_EQ(a.pairs, brute_force(mesh)) << "frame " << frame;
    EXPECT_EQ(a.rebuilt, frame == 0);
    EXPECT_TRUE(b.rebuilt);
    for (auto& p : mesh.positions) p = p + geom::Vec3d{double(step(rng)), double(step(rng)), double(step(rng))};
  }
  EXPECT_EQ(refitting.rebuild_count(), 0);
  EXPECT_EQ(rebuilding.rebuild_count(), 5);
}

TEST(Detect, AutomaticRebuildHappensWhenTheTreeDegrades) {
  // Scatter a tidy grid: refit boxes balloon and the policy must rebuild.
  SmallMesh mesh = folded_grid(20, 20);
  detect::Checker checker(detect::make_cpu_backend(2), std::make_shared<IntegerResolver>());
  checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  checker.check(mesh.positions);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> far(-1000, 1000);
  for (auto& p : mesh.positions) p = {double(far(rng)), double(far(rng)), double(far(rng))};
  const detect::FrameResult scattered = checker.check(mesh.positions);
  EXPECT_TRUE(scattered.rebuilt);
  EXPECT_EQ(checker.rebuild_count(), 1);
  EXPECT_EQ(scattered.pairs, brute_force(mesh));
}

TEST(Detect, TopologyChangeRebuilds) {
  SmallMesh mesh = folded_grid(6, 4);
  detect::Checker checker(detect::make_cpu_backend(1), std::make_shared<IntegerResolver>());
  EXPECT_TRUE(checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size())));
  EXPECT_FALSE(checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size())));
  checker.check(mesh.positions);
  mesh.triangles.pop_back();
  EXPECT_TRUE(checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size())));
  const detect::FrameResult result = checker.check(mesh.positions);
  EXPECT_TRUE(result.rebuilt);
  EXPECT_EQ(result.pairs, brute_force(mesh));
}

TEST(Detect, EmptyAndSingleTriangleMeshes) {
  SmallMesh empty;
  empty.positions = {{0, 0, 0}};
  EXPECT_TRUE(check_mesh(empty).pairs.empty());
  SmallMesh one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{{0, 1, 2}}}};
  EXPECT_TRUE(check_mesh(one).pairs.empty());
}

}  // namespace
}  // namespace snag::test
