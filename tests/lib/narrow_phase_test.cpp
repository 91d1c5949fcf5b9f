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

}  // namespace
}  // namespace snag::test
