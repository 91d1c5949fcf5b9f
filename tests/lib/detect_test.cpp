// The whole CPU path against a brute-force O(n^2) reference, on random soups and meshes of
// small integer coordinates (full of exact contacts), for several thread counts; refit
// against rebuild.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "detect_cases.h"
#include "snag/detect/topology.h"

namespace snag::test {
namespace {

TEST(Detect, MatchesBruteForceOnLatticeSoups) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const int32_t n = 20 + static_cast<int32_t>(seed * 7 % 90);
    const SmallMesh mesh = lattice_soup(n, n + static_cast<int32_t>(seed % 3) * n,
                                        3 + static_cast<int>(seed % 5), seed);
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

TEST(Detect, BothWalkWidthsMatchBruteForce) {
  // Groups of 4 and of 8 leaves (the width a CPU with AVX2 runs; without AVX2 the 8-lane code
  // runs unaccelerated here), on soups with and without welded-out vertices alike.
  SCOPED_TRACE("this machine walks groups of " + std::to_string(detect::cpu_walk_lanes()));
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const int32_t n = 5 + static_cast<int32_t>(seed * 13 % 120);
    const SmallMesh mesh = lattice_soup(n, 2 * n, 3 + static_cast<int>(seed % 4), seed);
    const std::vector<detect::FacePair> expected = brute_force(mesh);
    for (auto width : {detect::CpuWalkWidth::four, detect::CpuWalkWidth::eight})
      for (int threads : {1, 2})
        ASSERT_EQ(check_mesh(mesh, threads, nullptr, width).pairs, expected)
            << "seed " << seed << " lanes " << detect::cpu_walk_lanes(width);
  }
  const SmallMesh grid = folded_grid(17, 9);
  for (auto width : {detect::CpuWalkWidth::four, detect::CpuWalkWidth::eight})
    EXPECT_EQ(check_mesh(grid, 2, nullptr, width).pairs, brute_force(grid));
}

TEST(Detect, RefitMatchesRebuildAndBruteForceAfterDeformation) {
  SmallMesh mesh = folded_grid(15, 10);
  auto resolver = std::make_shared<IntegerResolver>();
  detect::Checker refitting(detect::make_cpu_backend(2), resolver, {detect::RebuildPolicy::never});
  detect::Checker rebuilding(detect::make_cpu_backend(2), resolver,
                             {detect::RebuildPolicy::always});
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
    for (auto& p : mesh.positions)
      p = p + geom::Vec3d{double(step(rng)), double(step(rng)), double(step(rng))};
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

TEST(Detect, ATreeBuiltOnAZeroedFrameIsRebuiltOnTheFirstFrameWithExtent) {
  // Its quality is 0 (every box empty), so no ratio to it ever degrades: without this rule the
  // scattered frames after it kept a tree built on one point.
  SmallMesh mesh = folded_grid(20, 20);
  const std::vector<geom::Vec3d> sheet = mesh.positions;
  detect::Checker checker(detect::make_cpu_backend(2), std::make_shared<IntegerResolver>());
  checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  for (auto& p : mesh.positions) p = {0.0, 0.0, 0.0};
  const detect::FrameResult zeroed = checker.check(mesh.positions);
  EXPECT_EQ(zeroed.tree_quality, 0.0);
  EXPECT_EQ(zeroed.degenerate.size(), mesh.triangles.size());
  mesh.positions = sheet;
  const detect::FrameResult first = checker.check(mesh.positions);
  EXPECT_TRUE(first.rebuilt);
  EXPECT_EQ(checker.rebuild_count(), 1);
  EXPECT_EQ(first.pairs, brute_force(mesh));
  const detect::FrameResult second = checker.check(mesh.positions);  // nothing moved
  EXPECT_FALSE(second.rebuilt);
  EXPECT_EQ(checker.rebuild_count(), 1);
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

TEST(Detect, FansAboveTheListedValenceAreFoundByTheTraversal) {
  // A fan of 48 triangles winding twice around its centre, corners alternately above and below
  // the plane: its triangles intersect each other, the centre has valence 48 > 32, so those
  // pairs are not in the neighbour list and must come from the traversal, each exactly once.
  // A second fan of 8 (listed) shares a rim vertex with it.
  SmallMesh mesh;
  mesh.positions.push_back({0, 0, 0});
  const int rim = 48;
  for (int i = 0; i < rim; ++i) {
    const double angle = 4.0 * 3.14159265358979 * i / rim;  // two turns
    mesh.positions.push_back(
        {std::round(100 * std::cos(angle)), std::round(100 * std::sin(angle)), i % 2 ? 7.0 : -5.0});
  }
  for (int i = 0; i < rim; ++i) mesh.triangles.push_back({{0, 1 + i, 1 + (i + 1) % rim}});
  const int32_t hub = static_cast<int32_t>(mesh.positions.size());
  mesh.positions.push_back({100, 0, 30});
  for (int i = 0; i < 8; ++i) {
    const int32_t a = static_cast<int32_t>(mesh.positions.size());
    mesh.positions.push_back({100.0 + 40 * (i % 3) - 40, 40.0 * (i / 3) - 40, -20.0 + 9 * i});
    mesh.triangles.push_back({{hub, a, i == 0 ? 1 : a - 1}});
  }
  const detect::Topology topology =
      detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  ASSERT_FALSE(topology.every_vertex_listed);
  ASSERT_FALSE(topology.listed_vertex[0]);
  const std::vector<detect::FacePair> expected = brute_force(mesh);
  ASSERT_GT(expected.size(), 20u);
  for (int threads : {1, 2})
    for (auto width : {detect::CpuWalkWidth::four, detect::CpuWalkWidth::eight})
      EXPECT_EQ(check_mesh(mesh, threads, nullptr, width).pairs, expected)
          << threads << " threads, lanes " << detect::cpu_walk_lanes(width);
}

TEST(Detect, PilesOfCollapsedTrianglesAreDegenerateAndPairWithNothing) {
  // Their leaves have empty boxes (bvh::leaf_box), so no walk reaches them; on a vertex and
  // inside a face of the sheet, they would otherwise touch it.
  const int32_t piled = 500;
  const SmallMesh mesh = folded_grid_with_piles(piled);
  const auto n = static_cast<int32_t>(mesh.triangles.size());
  std::vector<int32_t> pile(static_cast<size_t>(piled));
  for (int32_t i = 0; i < piled; ++i) pile[i] = n - piled + i;
  const std::vector<detect::FacePair> expected = brute_force(mesh);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(expected, brute_force(folded_grid(12, 8)));
  for (int threads : {1, 2}) {
    const detect::FrameResult result = check_mesh(mesh, threads);
    EXPECT_EQ(result.pairs, expected) << threads << " threads";
    EXPECT_EQ(result.degenerate, pile) << threads << " threads";
    // The same candidates as the sheet alone: the piled triangles are none.
    EXPECT_EQ(result.candidate_pairs, check_mesh(folded_grid(12, 8), threads).candidate_pairs);
  }
}

TEST(Detect, TheScanCertifiesCollapsedTrianglesSoTheirEmptyBoxesLoseNoCandidate) {
  // The backends find candidates by overlapping boxes (the CPU's neighbour list aside), so a
  // triangle whose leaf box is empty must be in the scan's certain list: a caller that passes
  // only that list to detect (the CUDA tests' frame comparisons, bench gpu) would otherwise see
  // the backends differ on it.
  for (int32_t n : {10, 300, 2000}) {
    SmallMesh soup = random_soup(n, static_cast<uint32_t>(n), 0.5);
    const std::vector<int32_t> collapsed = collapse_soup_triangles(soup, 5, 2, {4.0, 4.0, 4.0});
    const detect::Topology topology =
        detect::make_topology(soup.triangles, static_cast<int32_t>(soup.positions.size()));
    auto backend = detect::make_cpu_backend(2);
    backend->set_topology(topology);  // held by reference
    backend->set_positions(soup.positions);
    const detect::DegeneracyScan scan = backend->scan_degenerate();
    EXPECT_EQ(scan.degenerate, collapsed) << "n=" << n;
    EXPECT_TRUE(scan.uncertain.empty()) << "n=" << n;
  }
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
