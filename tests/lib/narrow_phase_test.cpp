// Hand-built cases with exact expected pairs and kinds (the BRIEF's rules), each also under
// integer affine maps that move it off the coordinate planes.
#include <gtest/gtest.h>

#include <random>

#include "detect_fixture.h"

namespace snag::test {
namespace {

using detect::FacePair;
using detect::PairKind;
constexpr PairKind kCrossing = PairKind::crossing;
constexpr PairKind kTouching = PairKind::touching;

struct Case {
  const char* name;
  SmallMesh mesh;
  std::vector<FacePair> pairs;
  std::vector<int32_t> degenerate;
};

std::vector<Case> cases() {
  std::vector<Case> all;
  // A base triangle F in z = 0 with corners 0, 1, 2.
  const std::vector<geom::Vec3d> base = {{0, 0, 0}, {8, 0, 0}, {0, 8, 0}};
  auto with = [&](std::vector<geom::Vec3d> more) {
    std::vector<geom::Vec3d> p = base;
    p.insert(p.end(), more.begin(), more.end());
    return p;
  };
  all.push_back({"shared edge folded flat", {with({{4, 4, 0}}), {{{0, 1, 2}}, {{0, 1, 3}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"shared edge flat continuation", {with({{4, -4, 0}}), {{{0, 1, 2}}, {{1, 0, 3}}}}, {}, {}});
  all.push_back({"shared edge hinge", {with({{4, 4, 5}}), {{{0, 1, 2}}, {{0, 1, 3}}}}, {}, {}});
  all.push_back({"shared vertex, opposite edge piercing",
                 {with({{2, 2, -2}, {2, 2, 2}}), {{{0, 1, 2}}, {{0, 3, 4}}}}, {{0, 1, kCrossing}}, {}});
  all.push_back({"shared vertex only", {with({{-2, -2, 3}, {-3, 1, 4}}), {{{0, 1, 2}}, {{0, 3, 4}}}}, {}, {}});
  all.push_back({"shared vertex, edge lying in the face",
                 {with({{2, 2, 0}, {1, 1, 5}}), {{{0, 1, 2}}, {{0, 3, 4}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"shared vertex, coplanar outside the angle",
                 {with({{-2, -2, 0}, {-4, 1, 0}}), {{{0, 1, 2}}, {{0, 3, 4}}}}, {}, {}});
  all.push_back({"coplanar overlap", {with({{1, 1, 0}, {12, 1, 0}, {1, 12, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}}, {}});
  all.push_back({"coplanar, one inside the other", {with({{1, 1, 0}, {3, 1, 0}, {1, 3, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}}, {}});
  all.push_back({"coplanar apart", {with({{9, 9, 0}, {12, 9, 0}, {9, 12, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {}, {}});
  all.push_back({"vertex exactly on the face", {with({{2, 2, 0}, {3, 2, 4}, {2, 3, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}}, {}});
  all.push_back({"vertex exactly on an edge", {with({{4, 0, 0}, {5, -1, 4}, {4, 1, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}}, {}});
  all.push_back({"vertex a hair above the face", {with({{2, 2, 1}, {3, 2, 4}, {2, 3, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {}, {}});
  all.push_back({"edge exactly through an edge",
                 {with({{4, -2, 0}, {4, 2, 0}, {4, 0, 6}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {{0, 1, kTouching}}, {}});
  // X's edge 3-4 crosses F's edge 0-1 at (4, 0, 0), and X meets F's plane along a segment
  // that leaves F there: both straddle, contact at one point.
  all.push_back({"edge across an edge at a point",
                 {with({{4, -2, -2}, {4, 2, 2}, {6, -4, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"segment contact without passing through",
                 {with({{1, 1, 0}, {3, 1, 0}, {2, 1, 5}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"proper crossing", {with({{1, 1, -3}, {3, 1, 3}, {2, 4, 3}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kCrossing}}, {}});
  // Both straddle, and the two segments on the planes' line meet only at an end: (4, 0, 0).
  all.push_back({"straddling, segments meet at one point",
                 {with({{4, -4, -4}, {4, -4, 4}, {4, 0, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"duplicated face", {base, {{{0, 1, 2}}, {{1, 2, 0}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"zero-area face through a triangle",
                 {with({{1, 1, -3}, {2, 2, 0}, {3, 3, 3}}), {{{0, 1, 2}}, {{3, 4, 5}}}}, {}, {1}});
  all.push_back({"repeated corner", {with({{1, 1, -3}}), {{{0, 1, 2}}, {{3, 3, 0}}}}, {}, {1}});
  return all;
}

const int kIdentity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const int kShear[3][3] = {{1, 2, 0}, {0, 1, 3}, {1, 0, 1}};       // det 7
const int kMirror[3][3] = {{0, 1, 0}, {1, 0, 0}, {-2, 3, 1}};  // det -1: a reflection

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
    for (size_t i = 0; i < c.pairs.size(); ++i) EXPECT_EQ(result.pairs[i].kind, c.pairs[i].kind) << c.name;
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
    if (f3 == geom::Sign::uncertain) ++uncertain;
    else ASSERT_EQ(f3, e3) << "trial " << trial << " (seed 12345)";
    zero += e3 == geom::Sign::zero;
    for (int axis = 0; axis < 3; ++axis) {
      const geom::Sign e2 = exact.orient2d(0, 1, 2, axis), f2 = filtered.orient2d(0, 1, 2, axis);
      if (f2 != geom::Sign::uncertain) ASSERT_EQ(f2, e2) << "trial " << trial;
    }
  }
  EXPECT_GT(zero, 1000);
  (void)uncertain;
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
        const long double ux = (long double)b.x - a.x, uy = (long double)b.y - a.y, uz = (long double)b.z - a.z;
        const long double vx = (long double)c.x - a.x, vy = (long double)c.y - a.y, vz = (long double)c.z - a.z;
        const long double wx = (long double)e.x - a.x, wy = (long double)e.y - a.y, wz = (long double)e.z - a.z;
        const long double det = ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx);
        EXPECT_EQ(f, det > 0 ? geom::Sign::positive : (det < 0 ? geom::Sign::negative : geom::Sign::zero))
            << "i=" << i << " dz=" << dz;
      }
    }
  }
  EXPECT_LT(certain, 3 * 65);  // most of these are beyond the filter
}

}  // namespace
}  // namespace snag::test
