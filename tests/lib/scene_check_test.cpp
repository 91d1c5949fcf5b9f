// Checking scenes (several parts laid end to end, a tree each, chosen checks between them)
// against the brute-force reference of the whole mesh, kept to the pairs the checks ask for;
// parts that did not move are not refit and their checks' pairs are reused.
#include <gtest/gtest.h>

#include <random>

#include "scene_cases.h"
#include "snag/detect/topology.h"
#include "snag/error.h"

namespace snag::test {
namespace {

std::unique_ptr<detect::Checker> make_checker(
    int threads, detect::CpuWalkWidth width = detect::CpuWalkWidth::automatic) {
  return std::make_unique<detect::Checker>(detect::make_cpu_backend(threads, width),
                                           std::make_shared<IntegerResolver>());
}

TEST(SceneCheck, PairsAreTheBruteForcePairsOfTheChecksAsked) {
  const std::vector<std::vector<detect::PartCheck>> check_sets = {
      {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}},  // everything: the whole mesh's pairs
      {{0, 1}, {0, 2}},                                  // a cloth against two obstacles
      {{0, 0}, {0, 1}},                                  // a cloth, itself and a body
      {{1, 1}},                                          // one part alone
      {{2, 2}, {1, 2}},
  };
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    std::vector<SmallMesh> parts;
    for (int p = 0; p < 3; ++p) {
      const int32_t n = 10 + static_cast<int32_t>((seed * 13 + p * 7) % 50);
      parts.push_back(lattice_soup(n, n + p * 5, 3 + static_cast<int>(seed % 4), seed * 3 + p));
    }
    const Laid laid = lay_end_to_end(parts);
    for (const auto& checks : check_sets)
      for (int threads : {1, 3}) {
        // Both walk widths, alternately (groups of 4 and 8 leaves, within and between parts).
        const auto width =
            (seed + threads) % 2 ? detect::CpuWalkWidth::four : detect::CpuWalkWidth::eight;
        auto checker = make_checker(threads, width);
        checker->set_scene(laid.mesh.triangles, static_cast<int32_t>(laid.mesh.positions.size()),
                           laid.layout, checks);
        const detect::FrameResult result = checker->check(laid.mesh.positions);
        ASSERT_EQ(result.pairs, expected_pairs(laid, checks))
            << "seed " << seed << " checks " << checks.size() << " threads " << threads;
        ASSERT_EQ(result.checks.size(), checks.size());
        int64_t counted = 0;
        for (const detect::CheckOutcome& c : result.checks) counted += c.pairs;
        EXPECT_EQ(counted, static_cast<int64_t>(result.pairs.size()));
      }
  }
}

// A part without triangles has an empty tree: its checks find nothing and the others run as
// usual, frame after frame, while the parts with triangles move.
TEST(SceneCheck, APartWithoutTrianglesChecksAsEmpty) {
  for (const Laid& scene : scenes_with_an_empty_part()) {
    const std::vector<detect::PartCheck> checks = every_check(scene);
    for (int threads : {1, 2}) {
      auto checker = make_checker(threads);
      checker->set_scene(scene.mesh.triangles, static_cast<int32_t>(scene.mesh.positions.size()),
                         scene.layout, checks);
      Laid frame = scene;
      for (int f = 0; f < 3; ++f) {
        for (geom::Vec3d& p : frame.mesh.positions) p = p + geom::Vec3d{0.0, 0.0, double(f % 2)};
        const detect::FrameResult result = checker->check(frame.mesh.positions);
        ASSERT_EQ(result.pairs, expected_pairs(frame, checks))
            << scene.layout.part_count() << " parts, frame " << f;
        ASSERT_EQ(result.checks.size(), checks.size());
      }
    }
  }
}

TEST(SceneCheck, PartsWhoseTreesOnlyTouchStillMeetInEitherOrder) {
  // A cloth triangle and an obstacle triangle whose edges cross at one point, (4, 1, 0), where
  // the cloth's box begins in x and the obstacle's ends: the test of the two trees' roots
  // must count boxes that meet in a face as overlapping, whichever part comes first.
  const SmallMesh cloth{{{4, 0, 0}, {8, 0, 0}, {4, 4, 0}}, {{{0, 1, 2}}}};
  const SmallMesh obstacle{{{4, 1, -4}, {4, 1, 4}, {0, 1, 0}}, {{{0, 1, 2}}}};
  for (const auto& parts : {std::vector<SmallMesh>{cloth, obstacle}, {obstacle, cloth}}) {
    const Laid laid = lay_end_to_end(parts);
    const std::vector<detect::PartCheck> checks = {{0, 1}};
    ASSERT_EQ(expected_pairs(laid, checks).size(), 1u);  // touching, by brute force
    for (int threads : {1, 2}) {
      auto checker = make_checker(threads);
      checker->set_scene(laid.mesh.triangles, static_cast<int32_t>(laid.mesh.positions.size()),
                         laid.layout, checks);
      EXPECT_EQ(checker->check(laid.mesh.positions).pairs, expected_pairs(laid, checks));
    }
  }
}

TEST(SceneCheck, OnePartSceneIsTheSingleMeshCheck) {
  const SmallMesh mesh = folded_grid(11, 7);
  auto scene = make_checker(2), single = make_checker(2);
  detect::PartLayout layout;
  layout.triangle_begin = {0, static_cast<int32_t>(mesh.triangles.size())};
  layout.vertex_begin = {0, static_cast<int32_t>(mesh.positions.size())};
  scene->set_scene(mesh.triangles, static_cast<int32_t>(mesh.positions.size()), layout, {{0, 0}});
  single->set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  const detect::FrameResult a = scene->check(mesh.positions), b = single->check(mesh.positions);
  EXPECT_EQ(a.pairs, b.pairs);
  EXPECT_EQ(a.pairs, brute_force(mesh));
  EXPECT_EQ(a.candidate_pairs, b.candidate_pairs);
}

TEST(SceneCheck, StillPartsAreNotRefitAndTheirPairsAreReused) {
  // A folded cloth (part 0) over a still lattice body (part 1), then the cloth moves, then a
  // frozen frame.
  const SmallMesh cloth = folded_grid(9, 6);
  const SmallMesh body = lattice_soup(60, 40, 8, 7);
  Laid laid = lay_end_to_end({cloth, body});
  const std::vector<detect::PartCheck> checks = {{0, 0}, {0, 1}};
  auto checker = make_checker(2);
  checker->set_scene(laid.mesh.triangles, static_cast<int32_t>(laid.mesh.positions.size()),
                     laid.layout, checks);
  const detect::FrameResult first = checker->check(laid.mesh.positions);
  ASSERT_EQ(first.pairs, expected_pairs(laid, checks));
  EXPECT_TRUE(first.parts[0].rebuilt && first.parts[1].rebuilt);
  EXPECT_EQ(checker->build_count(), 2);

  // The cloth moves by a whole unit (still integer coordinates); the body does not.
  for (int32_t v = laid.layout.vertex_begin[0]; v < laid.layout.vertex_begin[1]; ++v)
    laid.mesh.positions[v].z += 1;
  const std::vector<uint8_t> cloth_moved = {1, 0};
  const detect::FrameResult second = checker->check({laid.mesh.positions, cloth_moved, {}, {}});
  ASSERT_EQ(second.pairs, expected_pairs(laid, checks));
  EXPECT_TRUE(second.parts[0].moved);
  EXPECT_FALSE(second.parts[1].moved);
  EXPECT_FALSE(second.parts[1].rebuilt);
  EXPECT_EQ(second.parts[1].refit_seconds, 0.0);
  EXPECT_FALSE(second.checks[0].reused);
  EXPECT_FALSE(second.checks[1].reused);
  EXPECT_EQ(checker->build_count(), 2);

  // Nothing moves: nothing is traversed, every pair is the last frame's.
  const std::vector<uint8_t> frozen = {0, 0};
  const detect::FrameResult third = checker->check({laid.mesh.positions, frozen, {}, {}});
  EXPECT_EQ(third.pairs, second.pairs);
  EXPECT_EQ(third.candidate_pairs, 0);
  EXPECT_TRUE(third.checks[0].reused && third.checks[1].reused);
  EXPECT_EQ(third.checks[0].pairs, second.checks[0].pairs);
  EXPECT_EQ(third.checks[1].pairs, second.checks[1].pairs);
}

TEST(SceneCheck, AnUnmovedPartKeepsItsSelfPairsWhileTheOtherMoves) {
  // Two folded sheets, each checked against itself and the other; only the second moves.
  const SmallMesh a = folded_grid(8, 5), b = folded_grid(7, 6);
  Laid laid = lay_end_to_end({a, b});
  const std::vector<detect::PartCheck> checks = {{0, 0}, {0, 1}, {1, 1}};
  auto checker = make_checker(2);
  checker->set_scene(laid.mesh.triangles, static_cast<int32_t>(laid.mesh.positions.size()),
                     laid.layout, checks);
  checker->check(laid.mesh.positions);
  for (int32_t v = laid.layout.vertex_begin[1]; v < laid.layout.vertex_begin[2]; ++v)
    laid.mesh.positions[v].x += 3;
  const std::vector<uint8_t> moved = {0, 1};
  const detect::FrameResult result = checker->check({laid.mesh.positions, moved, {}, {}});
  EXPECT_EQ(result.pairs, expected_pairs(laid, checks));
  EXPECT_TRUE(result.checks[0].reused);
  EXPECT_FALSE(result.checks[1].reused);
  EXPECT_FALSE(result.checks[2].reused);
}

TEST(SceneCheck, ALayoutThatSharesVerticesOrMissesTrianglesIsRefused) {
  const SmallMesh a = folded_grid(3, 3);
  Laid laid = lay_end_to_end({a, a});
  laid.mesh.triangles.back().v[0] = 0;  // part 1 uses part 0's vertex
  EXPECT_THROW(detect::make_scene_topology(laid.mesh.triangles,
                                           static_cast<int32_t>(laid.mesh.positions.size()),
                                           laid.layout, {{0, 1}}),
               InternalError);
  detect::PartLayout short_layout = laid.layout;
  short_layout.triangle_begin.back() -= 1;
  EXPECT_THROW(detect::make_scene_topology(lay_end_to_end({a, a}).mesh.triangles,
                                           static_cast<int32_t>(laid.mesh.positions.size()),
                                           short_layout, {{0, 1}}),
               InternalError);
  EXPECT_THROW(detect::make_scene_topology(lay_end_to_end({a, a}).mesh.triangles,
                                           static_cast<int32_t>(laid.mesh.positions.size()),
                                           laid.layout, {{0, 2}}),
               InternalError);
}

}  // namespace
}  // namespace snag::test
