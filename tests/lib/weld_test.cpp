// Welding: clusters by distance (transitive), smallest id as representative, checked against a
// brute-force O(n^2) reference; exact coincidence counting.
#include "snag/mesh/weld.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "snag/error.h"

namespace snag::mesh {
namespace {

using geom::Vec3d;
using Reps = std::vector<int32_t>;

/// Every pair compared, components by repeated relaxation to the smallest id.
Reps brute_force_representatives(const std::vector<Vec3d>& p, double tol) {
  const size_t n = p.size();
  Reps rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  bool changed = true;
  while (changed) {
    changed = false;
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        const Vec3d d = p[i] - p[j];
        if (geom::dot(d, d) <= tol * tol && rep[i] != rep[j]) {
          const int32_t m = std::min(rep[i], rep[j]);
          rep[i] = rep[j] = m;
          changed = true;
        }
      }
    }
  }
  return rep;
}

TEST(Weld, WeldedTrianglesTakeEveryCornersRepresentative) {
  const std::vector<geom::Tri> triangles = {{{0, 1, 2}}, {{3, 4, 5}}};
  // Vertices 3 and 4 sit on 1 and 2 (a seam exported twice).
  const std::vector<Vec3d> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},
                                        {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  const Reps rep = weld_representatives(positions, 0.0);
  const std::vector<geom::Tri> welded = welded_triangles(triangles, rep);
  ASSERT_EQ(welded.size(), 2u);
  EXPECT_EQ(welded[0].v[0], 0);
  EXPECT_EQ(welded[0].v[1], 1);
  EXPECT_EQ(welded[0].v[2], 2);
  EXPECT_EQ(welded[1].v[0], 1);
  EXPECT_EQ(welded[1].v[1], 2);
  EXPECT_EQ(welded[1].v[2], 5);
  // No representatives: the triangles as they are.
  const std::vector<geom::Tri> same = welded_triangles(triangles, {});
  EXPECT_EQ(same[1].v[0], 3);
  EXPECT_EQ(same[1].v[2], 5);
}

TEST(Weld, EmptyAndSingle) {
  EXPECT_TRUE(weld_representatives({}, 0.1).empty());
  const std::vector<Vec3d> one = {{1, 2, 3}};
  EXPECT_EQ(weld_representatives(one, 0.1), (Reps{0}));
  EXPECT_EQ(count_coincident_vertices({}), 0);
}

TEST(Weld, ZeroToleranceJoinsExactlyEqualPositions) {
  const std::vector<Vec3d> p = {{0, 0, 0},      {1, 0, 0}, {0, 0, 0},
                                {1, 0, 1e-300}, {1, 0, 0}, {-0.0, 0, 0}};
  EXPECT_EQ(weld_representatives(p, 0.0), (Reps{0, 1, 0, 3, 1, 0}));
}

TEST(Weld, DistanceEqualToTheToleranceJoins) {
  const std::vector<Vec3d> p = {{0, 0, 0}, {0.5, 0, 0}, {0.5, 0.75, 0}};
  EXPECT_EQ(weld_representatives(p, 0.5), (Reps{0, 0, 2}));
  EXPECT_EQ(weld_representatives(p, 0.4999), (Reps{0, 1, 2}));
  EXPECT_EQ(weld_representatives(p, 0.75), (Reps{0, 0, 0}));
}

TEST(Weld, ChainsAreTransitiveAndTheSmallestIdRepresents) {
  // A chain 0.9 apart listed out of order: every link is within 1, the ends 3.6 apart.
  const std::vector<Vec3d> p = {{2.7, 0, 0}, {9, 9, 9}, {0.9, 0, 0},
                                {3.6, 0, 0}, {0, 0, 0}, {1.8, 0, 0}};
  EXPECT_EQ(weld_representatives(p, 1.0), (Reps{0, 1, 0, 0, 0, 0}));
}

TEST(Weld, NeighboursAcrossCellBoundariesAndTheOrigin) {
  const std::vector<Vec3d> p = {
      {-1e-9, -1e-9, -1e-9}, {1e-9, 1e-9, 1e-9}, {0.002, 0, 0}, {0.00199, -0.001, 0}};
  // With tol 0.001 the cell is 0.002: point 2 sits exactly on a cell boundary.
  EXPECT_EQ(weld_representatives(p, 0.001), (Reps{0, 0, 2, 3}));
  EXPECT_EQ(weld_representatives(p, 0.0011), (Reps{0, 0, 2, 2}));
}

// Two points the tolerance apart as welding measures it, in doubles (0.1 - (-1e-18) rounds to
// 0.1), on either side of the origin: cells as wide as the tolerance would put them two cells
// apart (floor(-1e-18 / 0.1) = -1, floor(0.1 / 0.1) = 1), cells of twice it keep them neighbours.
TEST(Weld, PointsTheToleranceApartAcrossTheOriginJoin) {
  const std::vector<Vec3d> p = {{-1e-18, 0, 0}, {0.1, 0, 0}};
  EXPECT_EQ(brute_force_representatives(p, 0.1), (Reps{0, 0}));
  EXPECT_EQ(weld_representatives(p, 0.1), (Reps{0, 0}));
}

// Exporters write "-0.000000": a vertex at x = -0.0 must be found from the cell on its other
// side as one at +0.0 is (a cell key of -0.0 would hash apart from the 0.0 that the neighbour's
// lookup makes). Many pairs, so that a miss cannot hide in a shared hash bucket.
TEST(Weld, NegativeZeroCoordinatesMeetTheirNeighbours) {
  std::vector<Vec3d> p;
  Reps expected;
  for (int32_t i = 0; i < 200; ++i) {
    p.push_back({-0.0, 3.0 * i, -0.0});
    p.push_back({-0.05, 3.0 * i, 0.01});  // 0.051 away; the next pair is 3 away
    expected.insert(expected.end(), {2 * i, 2 * i});
  }
  ASSERT_EQ(brute_force_representatives(p, 0.1), expected);
  EXPECT_EQ(weld_representatives(p, 0.1), expected);
}

TEST(Weld, LargeCoordinatesWithATinyTolerance) {
  const std::vector<Vec3d> p = {
      {1e15, -1e15, 3}, {1e15, -1e15, 3 + 1e-6}, {1e15 + 0.125, -1e15, 3}, {1e15, -1e15, 3}};
  EXPECT_EQ(weld_representatives(p, 1e-5), (Reps{0, 0, 2, 0}));
  // Far beyond 2^53 cells: only exact positions can be within the tolerance.
  const std::vector<Vec3d> q = {{1e300, 0, 0}, {1e300, 0, 0}, {-1e300, 1e-310, 0}, {-1e300, 0, 0}};
  EXPECT_EQ(weld_representatives(q, 1e-300), (Reps{0, 0, 2, 2}));
}

TEST(Weld, MatchesBruteForceOnRandomClouds) {
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    const size_t n = 200 + 50 * seed;
    std::vector<Vec3d> p;
    for (size_t i = 0; i < n; ++i) {
      // A third of the points are near copies of earlier ones, as on unwelded seams.
      if (i > 0 && rng() % 3 == 0) {
        const Vec3d q = p[rng() % i];
        const double e = 1e-4 * coord(rng);
        p.push_back({q.x + e, q.y - e, q.z});
      } else {
        p.push_back({coord(rng), coord(rng), coord(rng)});
      }
    }
    for (double tol : {0.0, 1e-5, 1e-4, 0.01, 0.05, 0.2}) {
      SCOPED_TRACE("tolerance " + std::to_string(tol));
      const Reps got = weld_representatives(p, tol);
      ASSERT_EQ(got, brute_force_representatives(p, tol));
      for (size_t i = 0; i < n; ++i) {
        ASSERT_LE(got[i], static_cast<int32_t>(i));
        ASSERT_EQ(got[got[i]], got[i]);
      }
    }
  }
}

TEST(Weld, RejectsBadTolerances) {
  const std::vector<Vec3d> p = {{0, 0, 0}};
  EXPECT_THROW(weld_representatives(p, -1e-6), UsageError);
  EXPECT_THROW(weld_representatives(p, std::numeric_limits<double>::quiet_NaN()), UsageError);
  EXPECT_THROW(weld_representatives(p, std::numeric_limits<double>::infinity()), UsageError);
}

TEST(CoincidentVertices, CountsVerticesEqualToAnEarlierOne) {
  const std::vector<Vec3d> p = {{0, 0, 0}, {1, 0, 0}, {0, 0, 0},    {0, 0, 0},
                                {2, 0, 0}, {1, 0, 0}, {1, 0, 1e-12}};
  EXPECT_EQ(count_coincident_vertices(p), 3);
  const std::vector<Vec3d> distinct = {{0, 0, 0}, {0, 0, 1e-300}, {0, 1e-300, 0}, {1e-300, 0, 0}};
  EXPECT_EQ(count_coincident_vertices(distinct), 0);
  // Signed zeros are one position.
  const std::vector<Vec3d> zeros = {{0.0, 0.0, 0.0}, {-0.0, 0.0, -0.0}};
  EXPECT_EQ(count_coincident_vertices(zeros), 1);
}

TEST(CoincidentVertices, AgreesWithZeroToleranceWelding) {
  std::mt19937 rng(7);
  std::vector<Vec3d> p;
  for (int i = 0; i < 2000; ++i) {
    if (i > 0 && rng() % 4 == 0) {
      p.push_back(p[rng() % i]);
    } else {
      p.push_back({static_cast<double>(rng() % 50), static_cast<double>(rng() % 50), 0.5});
    }
  }
  const Reps reps = weld_representatives(p, 0.0);
  int64_t joined = 0;
  for (size_t i = 0; i < p.size(); ++i) joined += reps[i] != static_cast<int32_t>(i);
  EXPECT_EQ(count_coincident_vertices(p), joined);
  EXPECT_GT(joined, 400);
}

}  // namespace
}  // namespace snag::mesh
