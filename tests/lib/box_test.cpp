// Outward rounding of double coordinates to float box bounds, against the library's
// nextafterf: float_down(x) is the largest float not above x, float_up(x) the smallest not below.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "snag/geom/box.h"

namespace snag::geom {
namespace {

float reference_down(double x) {
  float f = static_cast<float>(x);
  while (static_cast<double>(f) > x)
    f = std::nextafterf(f, -std::numeric_limits<float>::infinity());
  return f;
}

float reference_up(double x) {
  float f = static_cast<float>(x);
  while (static_cast<double>(f) < x) f = std::nextafterf(f, std::numeric_limits<float>::infinity());
  return f;
}

/// Same value and, for zeros, the same sign (a bound of -0.0 and one of +0.0 are both exact,
/// but the comparison makes sure the step rule saw the zero it expects).
void expect_same_float(float got, float want, double x) {
  EXPECT_TRUE(got == want && std::signbit(got) == std::signbit(want))
      << "x = " << x << " (" << std::hexfloat << x << "): got " << got << ", want " << want
      << std::defaultfloat;
}

std::vector<double> edge_values() {
  const double tiny = std::numeric_limits<double>::denorm_min();
  std::vector<double> values = {0.0,
                                -0.0,
                                tiny,
                                1e-300,
                                double(FLT_TRUE_MIN),
                                double(FLT_TRUE_MIN) / 2,
                                double(FLT_TRUE_MIN) * 1.5,
                                double(FLT_MIN),
                                std::nextafter(double(FLT_MIN), 0.0),
                                1.0,
                                std::nextafter(1.0, 2.0),
                                std::nextafter(1.0, 0.0),
                                0.1,
                                1.0 / 3.0,
                                double(FLT_MAX),
                                std::nextafter(double(FLT_MAX), 0.0),
                                std::nextafter(double(FLT_MAX), 1e300),
                                1e39,
                                1e300,
                                std::numeric_limits<double>::max()};
  const size_t positive = values.size();
  for (size_t i = 0; i < positive; ++i) values.push_back(-values[i]);
  return values;
}

TEST(Box, OutwardRoundingMatchesNextafterAtTheEdges) {
  for (double x : edge_values()) {
    expect_same_float(float_down(x), reference_down(x), x);
    expect_same_float(float_up(x), reference_up(x), x);
  }
}

TEST(Box, OutwardRoundingMatchesNextafterOnRandomDoubles) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-160, 140);
  for (int i = 0; i < 200000; ++i) {
    const double x = std::ldexp(mantissa(rng), exponent(rng));
    expect_same_float(float_down(x), reference_down(x), x);
    expect_same_float(float_up(x), reference_up(x), x);
    if (HasFailure()) return;
  }
}

TEST(Box, TriangleBoxContainsItsCornersExactly) {
  const Vec3d a{0.1, -1e-40, 3e38}, b{1.0 / 3.0, 2e-45, -0.7}, c{-0.0, 1.0, 1e39};
  const Box3f box = triangle_box(a, b, c);
  for (const Vec3d& p : {a, b, c})
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(double(box.lo[k]), coord(p, k));
      EXPECT_GE(double(box.hi[k]), coord(p, k));
    }
  EXPECT_EQ(box.lo[0], reference_down(-0.0));
  EXPECT_EQ(box.hi[2], std::numeric_limits<float>::infinity());
  EXPECT_EQ(box.lo[2], reference_down(-0.7));
}

TEST(Box, BoxesThatOnlyTouchOverlapOnEveryAxisInBothOrders) {
  // Triangles that touch at a point or along an edge intersect (BRIEF.md), and their boxes
  // may meet in a face and no more: overlap is closed on every side. One float further apart,
  // they do not.
  for (int axis = 0; axis < 3; ++axis)
    for (float at : {0.0f, 1.0f, -2.5f, 1e-30f, 3e30f}) {
      const float span = std::max(1.0f, std::fabs(at));  // boxes as wide as where they meet
      Box3f low{{-1e3f, -1e3f, -1e3f}, {1e3f, 1e3f, 1e3f}}, high = low;
      low.hi[axis] = at;
      low.lo[axis] = at - span;
      high.lo[axis] = at;
      high.hi[axis] = at + span;
      SCOPED_TRACE("axis " + std::to_string(axis) + " at " + std::to_string(at));
      EXPECT_TRUE(overlap(low, high));
      EXPECT_TRUE(overlap(high, low));
      high.lo[axis] = std::nextafter(at, std::numeric_limits<float>::infinity());
      EXPECT_FALSE(overlap(low, high));
      EXPECT_FALSE(overlap(high, low));
    }
}

TEST(Box, AnEmptyBoxOverlapsNoBoxShortOfFltMaxHasNoAreaAndLeavesMergesAlone) {
  const Box3f empty = empty_box();
  const Box3f point = triangle_box({1, 2, 3}, {1, 2, 3}, {1, 2, 3});
  const Box3f wide = triangle_box({-1e30, -1e30, -1e30}, {1e30, 1e30, 1e30}, {0, 0, 0});
  for (const Box3f& box : {point, wide, empty}) {
    EXPECT_FALSE(overlap(empty, box));
    EXPECT_FALSE(overlap(box, empty));
    EXPECT_TRUE(contains(box, empty));
  }
  EXPECT_EQ(half_area(empty), 0.0);
  EXPECT_EQ(half_area(merge(empty, empty)), 0.0);
  EXPECT_EQ(half_area(point), 0.0);
  const Box3f merged = merge(empty, wide);
  EXPECT_EQ(std::memcmp(&merged, &wide, sizeof wide), 0);
  EXPECT_EQ(half_area(merged), half_area(wide));
  EXPECT_GT(half_area(wide), 0.0);
}

}  // namespace
}  // namespace snag::geom
