// Hand-built cases with exact expected pairs and kinds (the BRIEF's rules), each also under
// integer affine maps that move it off the coordinate planes.
#include <gtest/gtest.h>

#include <random>

#include "detect_cases.h"

namespace snag::test {
namespace {

void expect_case(const Case& c, const int m[3][3], geom::Vec3d offset, int threads) {
  const SmallMesh mesh = transformed(c.mesh, m, offset);
  const detect::FrameResult result = check_mesh(mesh, threads);
  EXPECT_EQ(result.pairs, c.pairs) << c.name;
  EXPECT_EQ(result.degenerate, c.degenerate) << c.name;
}

TEST(HandBuilt, ExactPairsAndKinds) {
  for (const Case& c : cases()) {
    for (int threads : {1, 2}) {
      expect_case(c, kIdentity, {0, 0, 0}, threads);
      expect_case(c, kShear, {3, -5, 7}, threads);
      expect_case(c, kMirror, {-1000, 77, 5}, threads);
    }
  }
}

TEST(HandBuilt, AnswerDoesNotDependOnFaceOrderOrCornerRotation) {
  for (const Case& c : cases()) {
    if (c.mesh.triangles.size() != 2) continue;
    SmallMesh swapped = c.mesh;
    std::swap(swapped.triangles[0], swapped.triangles[1]);
    for (auto& t : swapped.triangles) t = {{t.v[1], t.v[2], t.v[0]}};
    const detect::FrameResult result = check_mesh(transformed(swapped, kShear, {1, 2, 3}));
    ASSERT_EQ(result.pairs.size(), c.pairs.size()) << c.name;
    for (size_t i = 0; i < c.pairs.size(); ++i)
      EXPECT_EQ(result.pairs[i].kind, c.pairs[i].kind) << c.name;
    std::vector<int32_t> degenerate;
    for (int32_t d : c.degenerate) degenerate.push_back(1 - d);
    EXPECT_EQ(result.degenerate, degenerate) << c.name;
  }
}

TEST(Predicates, FilterNeverGivesAWrongSignOnSmallIntegers) {
  // Small integer coordinates make every double operation exact, so the filter must answer
  // the exact sign or `uncertain`, and zero determinants with nonzero terms are plentiful.
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> coord(-4, 4);
  std::vector<geom::Vec3d> points(4);
  int uncertain = 0, zero = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    for (auto& p : points) p = {double(coord(rng)), double(coord(rng)), double(coord(rng))};
    const IntegerPredicates exact{points.data()};
    const geom::FilteredPredicates filtered{points.data()};
    const geom::Sign e3 = exact.orient3d(0, 1, 2, 3), f3 = filtered.orient3d(0, 1, 2, 3);
    if (f3 == geom::Sign::uncertain)
      ++uncertain;
    else
      ASSERT_EQ(f3, e3) << "trial " << trial << " (seed 12345)";
    zero += e3 == geom::Sign::zero;
    for (int axis = 0; axis < 3; ++axis) {
      const geom::Sign e2 = exact.orient2d(0, 1, 2, axis), f2 = filtered.orient2d(0, 1, 2, axis);
      if (f2 != geom::Sign::uncertain) ASSERT_EQ(f2, e2) << "trial " << trial;
    }
  }
  EXPECT_GT(zero, 1000);
  (void)uncertain;
}

TEST(Predicates, AnUnderflowedMinorIsNeverCertified) {
  // A minor of the plane underflows (2^-1080) and is then multiplied by 2^500: the computed
  // determinant is negative while the exact one, 2^-580 - 2^-601, is positive. The filter must
  // answer `uncertain` (or the right sign), never `negative`.
  const geom::Vec3d a{0, 0, 0}, b{0x1p-61, 0x1p-540, 0}, c{0, 0, 0x1p-540}, d{0x1p500, 1, 0};
  EXPECT_NE(geom::orient3d(a, b, c, d), geom::Sign::negative);
  EXPECT_EQ(geom::orient3d(a, b, c, d), geom::Sign::uncertain);
  // Tiny query differences against an ordinary plane: products near or below the underflow
  // threshold, whose signs must still be right when certified.
  EXPECT_EQ(geom::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0x1p-600, 0x1p-600, 0x1p-600}),
            geom::Sign::positive);
  EXPECT_NE(geom::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0x1p-1074, 1, 0x1p-1074}),
            geom::Sign::negative);
  EXPECT_NE(geom::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, -0x1p-1074}),
            geom::Sign::positive);
  // Ordinary inputs stay certain.
  EXPECT_EQ(geom::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.5, 1e-9}),
            geom::Sign::positive);
}

TEST(Predicates, NearDegenerateSignsAreUncertainNotWrong) {
  // d moved off the plane of a, b, c by one unit in the last place: tiny determinants whose
  // sign the double evaluation can get wrong; the filter must certify only correct ones.
  const geom::Vec3d a{0.1, 0.2, 0.3}, b{1.7, 0.3, 0.9}, c{0.4, 2.1, 0.5};
  int certain = 0;
  for (int i = 0; i <= 64; ++i) {
    const double t = i / 64.0, s = 1 - t;
    geom::Vec3d d{s * a.x + t * b.x, s * a.y + t * b.y, s * a.z + t * b.z};
    for (double dz : {-1.0, 0.0, 1.0}) {
      geom::Vec3d e{d.x, d.y, std::nextafter(d.z, d.z + dz)};
      if (dz == 0) e = d;
      const geom::Sign f = geom::orient3d(a, b, c, e);
      if (f != geom::Sign::uncertain) ++certain;
      // Where the filter is certain, the sign must agree with a long double re-evaluation
      // whose error is far below the filter's bound for these magnitudes.
      if (f != geom::Sign::uncertain) {
        const long double ux = (long double)b.x - a.x, uy = (long double)b.y - a.y,
                          uz = (long double)b.z - a.z;
        const long double vx = (long double)c.x - a.x, vy = (long double)c.y - a.y,
                          vz = (long double)c.z - a.z;
        const long double wx = (long double)e.x - a.x, wy = (long double)e.y - a.y,
                          wz = (long double)e.z - a.z;
        const long double det =
            ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx);
        EXPECT_EQ(
            f, det > 0 ? geom::Sign::positive : (det < 0 ? geom::Sign::negative : geom::Sign::zero))
            << "i=" << i << " dz=" << dz;
      }
    }
  }
  EXPECT_LT(certain, 3 * 65);  // most of these are beyond the filter
}

TEST(Predicates, TwoCoincidentCornersAreCertainlyDegenerate) {
  // A triangle with two corners at one point has an empty leaf box (bvh::leaf_box), which no
  // walk enters, so the scan must list it as degenerate without the exact stage: the filter
  // certifies orient2d's zero when two of its points coincide. With a == b and c elsewhere the
  // rounded products acx * bcy and acy * bcx are equal but not zero, and the bound alone left
  // the sign uncertain.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<geom::Vec3d> points(3);
    for (auto& p : points) p = {coordinate(rng), coordinate(rng), coordinate(rng)};
    const int same = trial % 3;  // which corner moves onto the next one
    points[same] = points[(same + 1) % 3];
    const geom::FilteredPredicates filtered{points.data()};
    ASSERT_EQ(geom::is_degenerate(filtered, 0, 1, 2), geom::Answer::yes) << "trial " << trial;
    for (int axis = 0; axis < 3; ++axis)
      ASSERT_EQ(filtered.orient2d(0, 1, 2, axis), geom::Sign::zero) << "trial " << trial;
  }
  // Points that differ, however little, are still left to the exact stage when the filter
  // cannot tell.
  const std::vector<geom::Vec3d> near{
      {0.1, 0.2, 0.3}, {std::nextafter(0.1, 1.0), 0.2, 0.3}, {0.7, 1.1, 0.3}};
  EXPECT_NE(geom::orient2d(near[0], near[1], near[2], 2), geom::Sign::zero);
}

/// Random pairs of triangles on a small integer grid (many touching configurations: ends of
/// the two segments that coincide, edges through the other's edges or corners), six vertices,
/// no vertex shared. Calls f(points, sides of the first against the second's plane, sides of
/// the second) for each pair whose triangles straddle each other's planes strictly.
template <class F>
void for_each_straddling_pair(uint32_t seed, int trials, int extent, F&& f) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(-extent, extent);
  std::vector<geom::Vec3d> points(6);
  const geom::Tri a{{0, 1, 2}}, b{{3, 4, 5}};
  for (int trial = 0; trial < trials; ++trial) {
    for (auto& p : points) p = {double(coord(rng)), double(coord(rng)), double(coord(rng))};
    const IntegerPredicates exact{points.data()};
    if (geom::is_degenerate(exact, 0, 1, 2) != geom::Answer::no ||
        geom::is_degenerate(exact, 3, 4, 5) != geom::Answer::no)
      continue;
    geom::Sign sa[3], sb[3];
    geom::corner_sides(exact, a, b, sa);
    geom::corner_sides(exact, b, a, sb);
    if (!geom::strict_sides(sa) || !geom::strict_sides(sb) || geom::lone_corner(sa) < 0 ||
        geom::lone_corner(sb) < 0)
      continue;
    f(points, sa, sb);
  }
}

/// The edge-by-edge answers of f's edges against x (edge k: corners k, k + 1).
template <class P>
void edge_answers(const P& pred, const geom::Tri& f, const geom::Tri& x, const geom::Sign side[3],
                  geom::Answer answers[3]) {
  for (int k = 0; k < 3; ++k)
    answers[k] =
        geom::edge_hits_triangle(pred, f.v[k], f.v[(k + 1) % 3], x, side[k], side[(k + 1) % 3]);
}

TEST(StraddlingEdgeHits, ExactlyTheEdgeTestsAnswers) {
  // With exact predicates the joint decision answers every edge as the edge tests do,
  // touching configurations (zero orientations among its four) included.
  const geom::Tri a{{0, 1, 2}}, b{{3, 4, 5}};
  int pairs = 0, hits = 0, touching = 0;
  for_each_straddling_pair(
      2024, 400000, 3,
      [&](const std::vector<geom::Vec3d>& points, const geom::Sign sa[3], const geom::Sign sb[3]) {
        const IntegerPredicates exact{points.data()};
        geom::Answer joint_a[3], joint_b[3], edges_a[3], edges_b[3];
        ASSERT_TRUE(geom::straddling_edge_hits(exact, a, b, sa, sb, joint_a, joint_b));
        edge_answers(exact, a, b, sa, edges_a);
        edge_answers(exact, b, a, sb, edges_b);
        for (int k = 0; k < 3; ++k) {
          ASSERT_EQ(joint_a[k], edges_a[k])
              << "pair " << pairs << ", edge " << k << " of the first";
          ASSERT_EQ(joint_b[k], edges_b[k])
              << "pair " << pairs << ", edge " << k << " of the second";
          hits += (edges_a[k] == geom::Answer::yes) + (edges_b[k] == geom::Answer::yes);
        }
        // A hit count other than 0 or 2 is a segment end shared by the two segments.
        const int pair_hits =
            (edges_a[0] == geom::Answer::yes) + (edges_a[1] == geom::Answer::yes) +
            (edges_a[2] == geom::Answer::yes) + (edges_b[0] == geom::Answer::yes) +
            (edges_b[1] == geom::Answer::yes) + (edges_b[2] == geom::Answer::yes);
        touching += pair_hits != 0 && pair_hits != 2;
        ++pairs;
      });
  // The grid must have produced plenty of each kind of case.
  EXPECT_GT(pairs, 5000);
  EXPECT_GT(hits, 2000);
  EXPECT_GT(touching, 200);
}

TEST(StraddlingEdgeHits, FilteredAnswersAreExactOrDeferred) {
  // Through the double filter the joint decision either defers (returns false) or answers
  // what the exact edge tests answer; on a fine grid it defers rarely.
  const geom::Tri a{{0, 1, 2}}, b{{3, 4, 5}};
  for (const int extent : {3, 1 << 19}) {
    int pairs = 0, deferred = 0;
    for_each_straddling_pair(
        77 + extent, 200000, extent,
        [&](const std::vector<geom::Vec3d>& points, const geom::Sign sa[3],
            const geom::Sign sb[3]) {
          const IntegerPredicates exact{points.data()};
          const geom::FilteredPredicates filtered{points.data()};
          geom::Answer joint_a[3], joint_b[3], edges_a[3], edges_b[3];
          ++pairs;
          if (!geom::straddling_edge_hits(filtered, a, b, sa, sb, joint_a, joint_b)) {
            ++deferred;
            return;
          }
          edge_answers(exact, a, b, sa, edges_a);
          edge_answers(exact, b, a, sb, edges_b);
          for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(joint_a[k], edges_a[k]) << "extent " << extent << ", pair " << pairs;
            ASSERT_EQ(joint_b[k], edges_b[k]) << "extent " << extent << ", pair " << pairs;
          }
        });
    EXPECT_GT(pairs, 5000) << "extent " << extent;
    if (extent > 3) EXPECT_LT(deferred, pairs / 100) << "extent " << extent;
  }
}

}  // namespace
}  // namespace snag::test
