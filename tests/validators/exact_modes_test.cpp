// The --exact modes: `uncertain` and `all` agree everywhere and with CGAL's own answer; `all`
// decides everything exactly and confirms every pair, and a pair CGAL contradicts is an
// internal error; `off` counts its unproven decisions and can be wrong where it says so.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "snag/detect/checker.h"
#include "snag/detect/cpu_backend.h"
#include "snag/detect/resolve.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"
#include "snag/validators/exact_modes.h"
#include "test_paths.h"

namespace snag::validators {
namespace {

using detect::ExactMode;
using Pairs = std::vector<std::pair<int32_t, int32_t>>;

detect::FrameResult check(std::span<const geom::Vec3d> positions,
                          std::span<const geom::Tri> triangles, ExactMode mode, int threads = 2) {
  detect::CheckSettings settings;
  settings.exact = mode;
  auto checker = make_checker(detect::make_cpu_backend(threads), settings);
  checker->set_triangles(triangles, static_cast<int32_t>(positions.size()));
  return checker->check(positions);
}

struct Soup {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
};

/// Triangles on a coarse lattice scaled by a non-binary fraction and offset: exact contacts
/// whose coordinates are rounded, so the filter is often uncertain and rounding often wrong.
Soup rounded_lattice_soup(int32_t n, uint32_t seed, double scale, double offset) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(0, 4);
  std::uniform_int_distribution<int32_t> pick(0, n - 1);
  Soup soup;
  for (int32_t v = 0; v < n; ++v)
    soup.positions.push_back(
        {coord(rng) * scale + offset, coord(rng) * scale - offset, coord(rng) * scale + offset});
  for (int32_t t = 0; t < n; ++t) soup.triangles.push_back({{pick(rng), pick(rng), pick(rng)}});
  return soup;
}

TEST(ExactModes, ParseAndNameRoundTrip) {
  for (ExactMode mode : {ExactMode::off, ExactMode::uncertain, ExactMode::all})
    EXPECT_EQ(detect::parse_exact_mode(detect::to_string(mode)), mode);
  EXPECT_FALSE(detect::parse_exact_mode("exact"));
  EXPECT_FALSE(detect::parse_exact_mode(""));
}

TEST(ExactModes, UncertainAndAllAgreeWithEachOtherAndWithCgal) {
  int64_t deferred = 0;
  for (uint32_t seed = 1; seed <= 24; ++seed) {
    const Soup soup = rounded_lattice_soup(90, seed, seed % 2 ? 0.1 : 0.3, seed % 3 ? 0.7 : 1e6);
    const Pairs expected = cgal_soup_self_intersections(soup.positions, soup.triangles);
    for (int threads : {1, 3}) {
      const std::string what =
          "seed " + std::to_string(seed) + ", threads " + std::to_string(threads);
      const detect::FrameResult uncertain =
          check(soup.positions, soup.triangles, ExactMode::uncertain, threads);
      const detect::FrameResult all =
          check(soup.positions, soup.triangles, ExactMode::all, threads);
      ASSERT_EQ(uncertain.pairs, all.pairs) << what;  // kinds included
      ASSERT_EQ(uncertain.degenerate, all.degenerate) << what;
      ASSERT_EQ(pair_ids(all.pairs), expected) << what;
      // `all` decided every test exactly and confirmed every pair.
      EXPECT_EQ(all.filtered_tests, 0) << what;
      EXPECT_EQ(all.confirmed_pairs, static_cast<int64_t>(all.pairs.size())) << what;
      EXPECT_EQ(uncertain.confirmed_pairs, 0) << what;
      deferred += all.uncertain_tests;
    }
  }
  EXPECT_GT(deferred, 10000);
}

TEST(ExactModes, OffCountsItsUnprovenDecisionsAndIsWrongOnlyWhereItHadSome) {
  int seeds_wrong = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const Soup soup = rounded_lattice_soup(90, seed, 0.1, 0.7);
    const detect::FrameResult off = check(soup.positions, soup.triangles, ExactMode::off);
    const detect::FrameResult exact = check(soup.positions, soup.triangles, ExactMode::uncertain);
    const bool same = off.pairs == exact.pairs && off.degenerate == exact.degenerate;
    // Where the filter certified every sign, rounding decided nothing and off is exact.
    if (exact.uncertain_tests == 0) {
      EXPECT_TRUE(same) << "seed " << seed;
      EXPECT_EQ(off.uncertain_tests, 0) << "seed " << seed;
    }
    if (!same) {
      ++seeds_wrong;
      EXPECT_GT(off.uncertain_tests, 0) << "seed " << seed << ": off was wrong without saying";
    }
  }
  // Rounded exact contacts fool the rounded signs somewhere in 40 soups: the mode is not
  // silently exact.
  EXPECT_GT(seeds_wrong, 0);
}

TEST(ExactModes, AllOnSharedDataFilesMatchesUncertain) {
  const auto data = test::data_dir();
  if (data.empty())
    GTEST_SKIP() << "../shared/data is absent (set SNAG_DATA_DIR): skipping the data files";
  for (const char* file : {"ipc-toolkit/two-cubes-intersecting.ply",
                           "ipc-toolkit/thick-cloth/t1.ply", "scalable-ccd/cloth-funnel/227.ply"}) {
    const mesh::Mesh mesh = io::read_mesh(data / file);
    const detect::FrameResult all = check(mesh.positions, mesh.triangles, ExactMode::all);
    const detect::FrameResult uncertain =
        check(mesh.positions, mesh.triangles, ExactMode::uncertain);
    EXPECT_EQ(all.pairs, uncertain.pairs) << file;
    EXPECT_FALSE(all.pairs.empty()) << file;
    EXPECT_EQ(all.confirmed_pairs, static_cast<int64_t>(all.pairs.size())) << file;
  }
}

/// Two triangles: the second stands through the first (a crossing), and a third far away.
struct Three {
  std::vector<geom::Vec3d> positions{{0, 0, 0}, {4, 0, 0}, {0, 4, 0},  {1, 1, -1}, {1, 1, 1},
                                     {2, 2, 1}, {9, 9, 9}, {10, 9, 9}, {9, 10, 9}};
  std::vector<geom::Tri> triangles{{{0, 1, 2}}, {{3, 4, 5}}, {{6, 7, 8}}};
};

TEST(CgalConfirmer, ContradictsPairsThatDoNotIntersectOrHaveTheOtherKind) {
  const Three m;
  const detect::Topology topology = detect::make_topology(m.triangles, 9);
  const detect::ExactContext context{m.positions, &topology};
  auto confirmer = make_cgal_confirmer();
  const std::vector<detect::FacePair> right{{0, 1, detect::PairKind::crossing}};
  EXPECT_TRUE(confirmer->confirm(context, right).empty());
  const std::vector<detect::FacePair> wrong{{0, 1, detect::PairKind::touching},
                                            {0, 2, detect::PairKind::touching}};
  const std::vector<detect::Disagreement> found = confirmer->confirm(context, wrong);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].pair, wrong[0]);
  EXPECT_NE(found[0].what.find("crossing"), std::string::npos) << found[0].what;
  EXPECT_EQ(found[1].pair, wrong[1]);
  EXPECT_NE(found[1].what.find("no intersection"), std::string::npos) << found[1].what;
}

// The other way round: a pair said to cross that CGAL finds only touching (a corner resting on
// the other face) is contradicted as touching.
TEST(CgalConfirmer, NamesTouchingForAPairSaidToCrossThatOnlyTouches) {
  const std::vector<geom::Vec3d> positions{{0, 0, 0}, {4, 0, 0}, {0, 4, 0},
                                           {1, 1, 0}, {2, 1, 1}, {1, 2, 1}};
  const std::vector<geom::Tri> triangles{{{0, 1, 2}}, {{3, 4, 5}}};
  const detect::Topology topology = detect::make_topology(triangles, 6);
  const detect::ExactContext context{positions, &topology};
  auto confirmer = make_cgal_confirmer();
  const std::vector<detect::FacePair> touching{{0, 1, detect::PairKind::touching}};
  EXPECT_TRUE(confirmer->confirm(context, touching).empty());
  const std::vector<detect::FacePair> crossing{{0, 1, detect::PairKind::crossing}};
  const std::vector<detect::Disagreement> found = confirmer->confirm(context, crossing);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].pair, crossing[0]);
  EXPECT_NE(found[0].what.find("CGAL finds a touching pair"), std::string::npos) << found[0].what;
}

TEST(CgalConfirmer, ADisagreementIsAnInternalErrorNamingThePair) {
  // A confirmer that contradicts everything stands in for a bug in snag's decisions.
  struct Contrary final : detect::PairConfirmer {
    std::vector<detect::Disagreement> confirm(const detect::ExactContext&,
                                              std::span<const detect::FacePair> pairs) override {
      std::vector<detect::Disagreement> all;
      for (const auto& p : pairs) all.push_back({p, "contrary"});
      return all;
    }
  };
  const Three m;
  detect::CheckSettings settings;
  settings.exact = ExactMode::all;
  detect::Checker checker(detect::make_cpu_backend(1), make_cgal_resolver(), settings,
                          std::make_shared<Contrary>());
  checker.set_triangles(m.triangles, 9);
  try {
    checker.check(m.positions);
    FAIL() << "a contradicted pair must be an internal error";
  } catch (const InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("(0, 1, crossing: contrary)"), std::string::npos)
        << e.what();
  }
  // Mode all without a confirmer is refused outright.
  EXPECT_THROW(detect::Checker(detect::make_cpu_backend(1), make_cgal_resolver(), settings),
               InternalError);
}

TEST(ExactModes, FramesVouchedFiniteGiveTheSameAnswers) {
  // FrameInput::finite skips the guard below and nothing else: the same pairs, kinds and
  // degenerate faces on a soup with every kind of contact, over two frames (the second a refit).
  Soup soup = rounded_lattice_soup(300, 7, 0.1, 0.3);
  std::vector<geom::Vec3d> moved = soup.positions;
  for (geom::Vec3d& p : moved) p.z += 0.01 * p.x;
  for (ExactMode mode : {ExactMode::off, ExactMode::uncertain, ExactMode::all}) {
    detect::CheckSettings settings;
    settings.exact = mode;
    auto guarded = make_checker(detect::make_cpu_backend(2), settings);
    auto vouched = make_checker(detect::make_cpu_backend(2), settings);
    guarded->set_triangles(soup.triangles, static_cast<int32_t>(soup.positions.size()));
    vouched->set_triangles(soup.triangles, static_cast<int32_t>(soup.positions.size()));
    for (const auto* frame : {&soup.positions, &moved}) {
      const detect::FrameResult a = guarded->check(*frame);
      detect::FrameInput input;
      input.positions = *frame;
      input.finite = true;
      const detect::FrameResult b = vouched->check(input);
      ASSERT_FALSE(a.pairs.empty());
      EXPECT_EQ(a.pairs, b.pairs) << detect::to_string(mode);
      EXPECT_EQ(a.degenerate, b.degenerate) << detect::to_string(mode);
    }
  }
}

TEST(ExactModes, NanAndInfinityAreInputErrorsInEveryMode) {
  // Readers reject such files; the checker itself must not answer (NaN compares false, so
  // pairs vanish) nor crash (CGAL traps converting infinity to an exact number).
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()})
    for (ExactMode mode : {ExactMode::off, ExactMode::uncertain, ExactMode::all}) {
      Three m;
      m.positions[5].x = bad;
      try {
        check(m.positions, m.triangles, mode);
        FAIL() << "accepted " << bad << " with --exact " << detect::to_string(mode);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 5"), std::string::npos) << e.what();
      }
    }
}

}  // namespace
}  // namespace snag::validators
