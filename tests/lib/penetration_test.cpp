// Penetration of points into a closed obstacle against brute force: inside/outside from the
// generalized winding number (signed solid angles), depth from the minimum distance to every
// triangle; on a cube, an icosphere, a torus and a moving, deforming obstacle. Closedness
// messages on hand-broken cubes, and the statistics on a hand-computable case.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <utility>

#include "snag/error.h"
#include "snag/measure/penetration.h"

namespace snag::measure {
namespace {

using geom::Tri;
using geom::Vec3d;

struct Surface {
  std::vector<Vec3d> positions;
  std::vector<Tri> triangles;
  int32_t vertex_count() const { return static_cast<int32_t>(positions.size()); }
};

// ---------------------------------------------------------------------------------------------
// Meshes.

/// The unit cube [0, 1]^3, vertex x + 2y + 4z at (x, y, z), outward: faces -z, +z, -y, +y,
/// -x, +x, two triangles each (triangles 0 .. 11).
Surface cube() {
  Surface s;
  for (int i = 0; i < 8; ++i)
    s.positions.push_back({double(i & 1), double(i >> 1 & 1), double(i >> 2)});
  const int32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                               {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.triangles.push_back({{q[0], q[1], q[2]}});
    s.triangles.push_back({{q[0], q[2], q[3]}});
  }
  return s;
}

/// The icosahedron subdivided `levels` times (20 * 4^levels triangles), on the sphere of
/// `radius` around `center`, outward.
Surface icosphere(int levels, double radius, Vec3d center) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> unit = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                             {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                             {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Tri> tris = {{{0, 11, 5}}, {{0, 5, 1}},  {{0, 1, 7}},   {{0, 7, 10}}, {{0, 10, 11}},
                           {{1, 5, 9}},  {{5, 11, 4}}, {{11, 10, 2}}, {{10, 7, 6}}, {{7, 1, 8}},
                           {{3, 9, 4}},  {{3, 4, 2}},  {{3, 2, 6}},   {{3, 6, 8}},  {{3, 8, 9}},
                           {{4, 9, 5}},  {{2, 4, 11}}, {{6, 2, 10}},  {{8, 6, 7}},  {{9, 8, 1}}};
  auto normalize = [](Vec3d v) { return (1.0 / std::sqrt(geom::dot(v, v))) * v; };
  for (Vec3d& v : unit) v = normalize(v);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int32_t, int32_t>, int32_t> middle;
    auto mid = [&](int32_t a, int32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, fresh] = middle.try_emplace({key.first, key.second}, 0);
      if (fresh) {
        it->second = static_cast<int32_t>(unit.size());
        unit.push_back(normalize(unit[a] + unit[b]));
      }
      return it->second;
    };
    std::vector<Tri> finer;
    for (const Tri& tri : tris) {
      const int32_t a = tri.v[0], b = tri.v[1], c = tri.v[2];
      const int32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      finer.push_back({{a, ab, ca}});
      finer.push_back({{b, bc, ab}});
      finer.push_back({{c, ca, bc}});
      finer.push_back({{ab, bc, ca}});
    }
    tris = std::move(finer);
  }
  Surface s;
  for (const Vec3d& v : unit) s.positions.push_back(center + radius * v);
  s.triangles = std::move(tris);
  return s;
}

/// A torus around the z axis (major radius R, minor r), nu x nv quads, outward.
Surface torus(double major, double minor, int nu, int nv) {
  Surface s;
  const double two_pi = 2.0 * std::numbers::pi;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = two_pi * i / nu, v = two_pi * j / nv;
      s.positions.push_back({(major + minor * std::cos(v)) * std::cos(u),
                             (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v)});
    }
  auto id = [&](int i, int j) { return static_cast<int32_t>((i % nu) * nv + (j % nv)); };
  // (i, j) -> (i + 1, j) -> (i + 1, j + 1): u then v, whose cross product points outward.
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      s.triangles.push_back({{id(i, j), id(i + 1, j), id(i + 1, j + 1)}});
      s.triangles.push_back({{id(i, j), id(i + 1, j + 1), id(i, j + 1)}});
    }
  return s;
}

double signed_volume(const Surface& s) {
  double six_v = 0.0;
  for (const Tri& t : s.triangles)
    six_v += geom::dot(s.positions[t.v[0]], geom::cross(s.positions[t.v[1]], s.positions[t.v[2]]));
  return six_v / 6.0;
}

// ---------------------------------------------------------------------------------------------
// The brute-force reference, independent of the library's method.

/// Generalized winding number: the signed solid angles of all triangles seen from p (Van
/// Oosterom and Strackee, tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| +
/// (c.a)|b|)) over 4 pi. About +-1 inside a closed surface, 0 outside.
double winding_number(Vec3d p, const Surface& s) {
  double total = 0.0;
  for (const Tri& t : s.triangles) {
    const Vec3d a = s.positions[t.v[0]] - p, b = s.positions[t.v[1]] - p,
                c = s.positions[t.v[2]] - p;
    const double la = std::sqrt(geom::dot(a, a)), lb = std::sqrt(geom::dot(b, b)),
                 lc = std::sqrt(geom::dot(c, c));
    const double num = geom::dot(a, geom::cross(b, c));
    const double den =
        la * lb * lc + geom::dot(a, b) * lc + geom::dot(b, c) * la + geom::dot(c, a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * std::numbers::pi);
}

double segment_distance(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a;
  const double t = std::clamp(geom::dot(p - a, ab) / geom::dot(ab, ab), 0.0, 1.0);
  const Vec3d d = p - (a + t * ab);
  return std::sqrt(geom::dot(d, d));
}

/// Distance from p to triangle abc: to its plane when p projects inside the triangle (the
/// three edge-side tests agree with the normal), else to the nearest of its three edges.
double triangle_distance(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d n = geom::cross(b - a, c - a);
  const bool inside = geom::dot(geom::cross(b - a, p - a), n) >= 0.0 &&
                      geom::dot(geom::cross(c - b, p - b), n) >= 0.0 &&
                      geom::dot(geom::cross(a - c, p - c), n) >= 0.0;
  if (inside) return std::abs(geom::dot(p - a, n)) / std::sqrt(geom::dot(n, n));
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

double surface_distance(Vec3d p, const Surface& s) {
  double best = INFINITY;
  for (const Tri& t : s.triangles)
    best = std::min(
        best, triangle_distance(p, s.positions[t.v[0]], s.positions[t.v[1]], s.positions[t.v[2]]));
  return best;
}

std::vector<Vec3d> random_points(const Surface& s, int count, uint32_t seed) {
  Vec3d lo = s.positions[0], hi = s.positions[0];
  for (const Vec3d& v : s.positions) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  const Vec3d margin = 0.25 * (hi - lo);
  lo = lo - margin, hi = hi + margin;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3d> points;
  for (int i = 0; i < count; ++i)
    points.push_back({lo.x + unit(rng) * (hi.x - lo.x), lo.y + unit(rng) * (hi.y - lo.y),
                      lo.z + unit(rng) * (hi.z - lo.z)});
  return points;
}

/// Measures `points` against `meter` (set to `s`) on 1 and 2 threads, checks that both agree
/// bit for bit and that each point's depth is the reference's: the distance to the surface
/// when the winding number says inside, else 0.
void expect_matches_reference(const PenetrationMeter& meter, const Surface& s,
                              const std::vector<Vec3d>& points, const std::string& what) {
  std::vector<double> depths, depths_two;
  const PenetrationStats stats = meter.measure(points, 1, &depths);
  const PenetrationStats stats_two = meter.measure(points, 2, &depths_two);
  ASSERT_EQ(depths, depths_two) << what;
  EXPECT_EQ(stats.inside, stats_two.inside) << what;
  EXPECT_EQ(stats.mean_depth, stats_two.mean_depth) << what;
  EXPECT_EQ(stats.p95_depth, stats_two.p95_depth) << what;
  ASSERT_EQ(depths.size(), points.size());
  int64_t inside = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double w = winding_number(points[i], s);
    const double distance = surface_distance(points[i], s);
    ASSERT_LT(std::abs(std::abs(w) - std::round(std::abs(w))), 1e-6) << what << " point " << i;
    const bool expected_inside = std::abs(w) > 0.5;
    inside += expected_inside;
    ASSERT_EQ(depths[i] > 0.0, expected_inside)
        << what << " point " << i << " (" << points[i].x << ", " << points[i].y << ", "
        << points[i].z << ") winding " << w << " distance " << distance;
    if (expected_inside) ASSERT_NEAR(depths[i], distance, 1e-12) << what << " point " << i;
  }
  EXPECT_EQ(stats.points, static_cast<int64_t>(points.size())) << what;
  EXPECT_EQ(stats.inside, inside) << what;
  EXPECT_GT(inside, 0) << what << ": no point inside, the test tests little";
  EXPECT_LT(inside, static_cast<int64_t>(points.size())) << what;
}

/// Points exactly at the vertices and (up to rounding) on the faces: never measurably inside.
void expect_surface_points_not_inside(const PenetrationMeter& meter, const Surface& s,
                                      uint32_t seed, const std::string& what) {
  std::vector<Vec3d> points = s.positions;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Tri& t : s.triangles) {
    double u = unit(rng), v = unit(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Vec3d a = s.positions[t.v[0]], b = s.positions[t.v[1]], c = s.positions[t.v[2]];
    points.push_back(a + u * (b - a) + v * (c - a));
    points.push_back(a + 0.5 * (b - a));  // an edge's midpoint
  }
  std::vector<double> depths;
  meter.measure(points, 2, &depths);
  for (size_t i = 0; i < s.positions.size(); ++i)
    ASSERT_EQ(depths[i], 0.0) << what << " vertex " << i;
  for (size_t i = s.positions.size(); i < points.size(); ++i)
    ASSERT_LT(depths[i], 1e-12) << what << " surface point " << i << " seed " << seed;
}

PenetrationMeter meter_for(const Surface& s) {
  EXPECT_EQ(why_not_closed(s.triangles, s.vertex_count()), std::nullopt);
  PenetrationMeter meter(s.triangles, s.vertex_count());
  meter.update_positions(s.positions, 2);
  return meter;
}

// ---------------------------------------------------------------------------------------------
// Against brute force.

TEST(Penetration, CubeMatchesWindingNumberAndBruteForceDistance) {
  const Surface s = cube();
  ASSERT_NEAR(signed_volume(s), 1.0, 1e-15);
  const PenetrationMeter meter = meter_for(s);
  for (uint32_t seed : {1u, 2u, 3u})
    expect_matches_reference(meter, s, random_points(s, 3000, seed),
                             "cube seed " + std::to_string(seed));
  expect_surface_points_not_inside(meter, s, 4, "cube");
}

TEST(Penetration, CubeFacePointsAreExactlyOnTheSurface) {
  const Surface s = cube();
  const PenetrationMeter meter = meter_for(s);
  std::vector<Vec3d> points;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      const double x = i / 8.0, y = j / 8.0;  // exact: every face, its edges and corners
      for (double side : {0.0, 1.0}) {
        points.push_back({x, y, side});
        points.push_back({x, side, y});
        points.push_back({side, x, y});
      }
    }
  std::vector<double> depths;
  const PenetrationStats stats = meter.measure(points, 2, &depths);
  EXPECT_EQ(stats.inside, 0);
  for (size_t i = 0; i < points.size(); ++i) ASSERT_EQ(depths[i], 0.0) << "point " << i;
}

TEST(Penetration, IcosphereMatchesWindingNumberAndBruteForceDistance) {
  const Surface s = icosphere(4, 1.3, {0.1, -0.2, 0.3});
  ASSERT_EQ(s.triangles.size(), 5120u);
  ASSERT_GT(signed_volume(s), 0.0);
  const PenetrationMeter meter = meter_for(s);
  expect_matches_reference(meter, s, random_points(s, 2000, 11), "icosphere");
  // Points close to the surface, where the closest feature is often an edge or a vertex.
  std::vector<Vec3d> near = random_points(s, 2000, 12);
  for (Vec3d& p : near) {
    const Vec3d d = p - Vec3d{0.1, -0.2, 0.3};
    const double length = std::sqrt(geom::dot(d, d));
    p = Vec3d{0.1, -0.2, 0.3} + ((1.3 + 0.02 * (length - 1.3) / 1.3) / length) * d;
  }
  expect_matches_reference(meter, s, near, "icosphere near the surface");
  expect_surface_points_not_inside(meter, s, 13, "icosphere");
}

// The same scene at any magnitude gives the same points inside and depths scaled with it (found
// by fuzzing: past 1e80 or under 1e-100 a face's squared normal overflowed or underflowed, and
// no point was inside).
TEST(Penetration, DepthsScaleWithTheCoordinatesAtEveryMagnitude) {
  const Surface s = icosphere(3, 1.3, {0.1, -0.2, 0.3});
  const std::vector<Vec3d> points = random_points(s, 2000, 31);
  std::vector<double> base;
  const PenetrationStats base_stats = meter_for(s).measure(points, 2, &base);
  ASSERT_GT(base_stats.inside, 0);
  for (double scale :
       {0x1p-400, 0x1p-200, 1e-150, 0x1p-101, 1e-20, 1e20, 0x1p101, 1e130, 0x1p200, 0x1p400}) {
    SCOPED_TRACE(scale);
    Surface scaled_surface = s;
    for (Vec3d& v : scaled_surface.positions) v = scale * v;
    std::vector<Vec3d> scaled_points = points;
    for (Vec3d& p : scaled_points) p = scale * p;
    PenetrationMeter meter = meter_for(scaled_surface);
    EXPECT_GT(meter.enclosed_volume(), 0.0);  // its sign kept where scale^3 underflows
    // A second frame, the same positions, through a Clearance: the same depths, and the
    // points proven outside by the first are skipped.
    Clearance clearance;
    for (int frame = 0; frame < 2; ++frame) {
      if (frame == 1) meter.update_positions(scaled_surface.positions, 2);
      std::vector<double> depths;
      const PenetrationStats stats = meter.measure(scaled_points, clearance, 2, &depths);
      EXPECT_EQ(stats.inside, base_stats.inside);
      EXPECT_EQ(stats.proven_outside > 0, frame == 1);
      for (size_t i = 0; i < points.size(); ++i) {
        ASSERT_EQ(depths[i] > 0.0, base[i] > 0.0) << "point " << i << " frame " << frame;
        ASSERT_NEAR(depths[i] / scale, base[i], 1e-12) << "point " << i << " frame " << frame;
      }
    }
    // Inside out, however small: the volume says so.
    Surface reversed = scaled_surface;
    for (Tri& t : reversed.triangles) std::swap(t.v[1], t.v[2]);
    PenetrationMeter reversed_meter(reversed.triangles, reversed.vertex_count());
    reversed_meter.update_positions(reversed.positions, 2);
    EXPECT_LT(reversed_meter.enclosed_volume(), 0.0);
  }
}

TEST(Penetration, TorusMatchesWindingNumberAndBruteForceDistance) {
  const Surface s = torus(1.0, 0.35, 48, 24);
  ASSERT_GT(signed_volume(s), 0.0);
  const PenetrationMeter meter = meter_for(s);
  expect_matches_reference(meter, s, random_points(s, 3000, 21), "torus");
  // The hole: points on the axis are outside although surrounded.
  std::vector<double> depths;
  meter.measure(std::vector<Vec3d>{{0, 0, 0}, {0, 0, 0.2}, {1.0, 0, 0}}, 1, &depths);
  EXPECT_EQ(depths[0], 0.0);
  EXPECT_EQ(depths[1], 0.0);
  EXPECT_GT(depths[2], 0.3);
  expect_surface_points_not_inside(meter, s, 22, "torus");
}

TEST(Penetration, SpikyStarMatchesWindingNumberAndBruteForceDistance) {
  // An icosphere with every vertex pushed radially to a random radius: still embedded (each
  // ray from the center meets one triangle), with sharp convex and concave edges and
  // vertices, where only the right pseudonormal gives the right side.
  for (uint32_t seed : {41u, 42u, 43u}) {
    Surface s = icosphere(2, 1.0, {0, 0, 0});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> radius(0.4, 1.6);
    for (Vec3d& v : s.positions) v = radius(rng) * v;
    ASSERT_GT(signed_volume(s), 0.0);
    const PenetrationMeter meter = meter_for(s);
    expect_matches_reference(meter, s, random_points(s, 5000, seed + 100),
                             "star seed " + std::to_string(seed));
    expect_surface_points_not_inside(meter, s, seed + 200, "star seed " + std::to_string(seed));
  }
}

TEST(Penetration, MovingDeformingObstacleIsRefitAndMatchesReference) {
  Surface s = torus(1.0, 0.35, 40, 20);
  PenetrationMeter refitting = meter_for(s);
  const std::vector<Vec3d> rest = s.positions;
  // Points around every frame's obstacle.
  Surface span = s;
  for (Vec3d& v : span.positions) v = v + Vec3d{0.4, -0.3, 0.2};
  std::vector<Vec3d> points = random_points(s, 1000, 31);
  const std::vector<Vec3d> more = random_points(span, 1000, 32);
  points.insert(points.end(), more.begin(), more.end());
  for (int frame = 1; frame <= 4; ++frame) {
    // Translate and stretch: the tree's leaf order no longer fits the boxes well, and refit
    // must still give exact answers.
    const double f = frame / 4.0;
    for (size_t i = 0; i < rest.size(); ++i)
      s.positions[i] = Vec3d{rest[i].x * (1.0 + 0.2 * f), rest[i].y, rest[i].z * (1.0 - 0.3 * f)} +
                       Vec3d{0.4 * f, -0.3 * f, 0.2 * f};
    refitting.update_positions(s.positions, 2);
    const std::string what = "frame " + std::to_string(frame);
    expect_matches_reference(refitting, s, points, what);
    std::vector<double> refit_depths, built_depths;
    refitting.measure(points, 2, &refit_depths);
    meter_for(s).measure(points, 2, &built_depths);
    for (size_t i = 0; i < points.size(); ++i)
      ASSERT_NEAR(refit_depths[i], built_depths[i], 1e-15) << what << " point " << i;
  }
}

TEST(Penetration, ClearanceSkipsOnlyPointsProvenOutside) {
  // A torus that slides and swells, and points that drift (small steps, some large jumps
  // across the surface): measured with a Clearance, every frame's depths equal measure()'s
  // bit for bit, while far points are skipped.
  Surface s = torus(1.0, 0.35, 40, 20);
  PenetrationMeter meter = meter_for(s);
  const std::vector<Vec3d> rest = s.positions;
  std::vector<Vec3d> points = random_points(s, 3000, 51);
  std::mt19937 rng(52);
  std::uniform_real_distribution<double> step(-0.004, 0.004);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  Clearance clearance, clearance_two;
  int64_t skipped = 0;
  double previous_travel = 0.0;
  for (int frame = 0; frame < 12; ++frame) {
    if (frame > 0) {
      const double f = frame / 12.0;
      double moved = 0.0;
      for (size_t i = 0; i < rest.size(); ++i) {
        const Vec3d next = (1.0 + 0.05 * f) * rest[i] + Vec3d{0.03 * f, 0.0, -0.02 * f};
        const Vec3d d = next - s.positions[i];
        moved = std::max(moved, std::sqrt(geom::dot(d, d)));
        s.positions[i] = next;
      }
      meter.update_positions(s.positions, 2);
      EXPECT_DOUBLE_EQ(meter.travel() - previous_travel, moved);
      previous_travel = meter.travel();
      for (Vec3d& p : points) p = p + Vec3d{step(rng), step(rng), step(rng)};
      for (int jump = 0; jump < 40; ++jump) {  // far enough to cross the tube's wall
        Vec3d& p = points[pick(rng)];
        p = p + Vec3d{10 * step(rng), 60 * step(rng), 10 * step(rng)};
      }
    }
    const std::string what = "frame " + std::to_string(frame);
    std::vector<double> expected, remembered, remembered_two;
    const PenetrationStats full = meter.measure(points, 2, &expected);
    const PenetrationStats stats = meter.measure(points, clearance, 1, &remembered);
    meter.measure(points, clearance_two, 2, &remembered_two);
    ASSERT_EQ(remembered, expected) << what;
    ASSERT_EQ(remembered_two, expected) << what;
    EXPECT_EQ(stats.inside, full.inside) << what;
    EXPECT_EQ(stats.p95_depth, full.p95_depth) << what;
    EXPECT_EQ(full.proven_outside, 0) << what;
    if (frame == 0) EXPECT_EQ(stats.proven_outside, 0);
    skipped += stats.proven_outside;
    if (frame == 6) expect_matches_reference(meter, s, points, what + " (reference)");
  }
  // Most random points in the torus's box sit farther from the surface than they move.
  EXPECT_GT(skipped, 11 * 3000 / 2);
  // Given to another meter, or with a list of another length, the clearance starts over.
  const PenetrationMeter other = meter_for(s);
  EXPECT_EQ(other.measure(points, clearance, 2).proven_outside, 0);
  EXPECT_GT(other.measure(points, clearance, 2).proven_outside, 0);
  points.resize(100);
  EXPECT_EQ(meter.measure(points, clearance, 2).proven_outside, 0);
  // A non-finite obstacle position proves nothing about travel: no point is skipped again.
  EXPECT_GT(meter.measure(points, clearance, 2).proven_outside, 0);
  s.positions[0].x = std::numeric_limits<double>::quiet_NaN();
  meter.update_positions(s.positions, 2);
  EXPECT_TRUE(std::isnan(meter.travel()));
  EXPECT_EQ(meter.measure(points, clearance, 2).proven_outside, 0);
}

TEST(Penetration, InsideOutSurfaceHasNegativeVolume) {
  Surface s = cube();
  for (Vec3d& v : s.positions) v = v + Vec3d{5, -3, 2};  // the volume does not depend on where
  EXPECT_DOUBLE_EQ(meter_for(s).enclosed_volume(), 1.0);
  for (Tri& t : s.triangles) std::swap(t.v[1], t.v[2]);
  const PenetrationMeter inverted = meter_for(s);
  EXPECT_DOUBLE_EQ(inverted.enclosed_volume(), -1.0);
  // Its complement is measured: the center is outside, a point beside the cube inside.
  std::vector<double> depths;
  inverted.measure(std::vector<Vec3d>{{5.5, -2.5, 2.5}, {7, -2.5, 2.5}}, 1, &depths);
  EXPECT_EQ(depths[0], 0.0);
  EXPECT_DOUBLE_EQ(depths[1], 1.0);
  // A torus's polygon is inscribed in the smooth one: a little less than 2 pi^2 R r^2.
  const double torus_volume = meter_for(torus(1.0, 0.35, 48, 24)).enclosed_volume();
  EXPECT_LT(torus_volume, 2 * std::numbers::pi * std::numbers::pi * 0.35 * 0.35);
  EXPECT_GT(torus_volume, 0.98 * 2 * std::numbers::pi * std::numbers::pi * 0.35 * 0.35);
}

TEST(Penetration, UsageErrors) {
  const Surface s = cube();
  PenetrationMeter meter(s.triangles, s.vertex_count());
  EXPECT_THROW(meter.measure(s.positions, 1), InternalError);
  EXPECT_THROW(meter.update_positions(std::vector<Vec3d>(7)), InternalError);
  meter.update_positions(s.positions, 1);
  std::vector<double> depths;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  meter.measure(std::vector<Vec3d>{{nan, 0.5, 0.5}, {0.5, INFINITY, 0.5}, {0.5, 0.5, 0.5}}, 1,
                &depths);
  EXPECT_EQ(depths, (std::vector<double>{0.0, 0.0, 0.5}));  // non-finite points measure 0
  std::vector<Tri> open = s.triangles;
  open.pop_back();
  EXPECT_THROW(PenetrationMeter(open, s.vertex_count()), InternalError);
}

// ---------------------------------------------------------------------------------------------
// Statistics.

TEST(Penetration, StatisticsOnAHandComputableCase) {
  const PenetrationMeter meter = meter_for(cube());
  // 20 inside, at depths 0.01 .. 0.20 above the bottom face (every other face is farther),
  // and 5 outside.
  std::vector<Vec3d> points;
  for (int i = 1; i <= 20; ++i) points.push_back({0.5, 0.5, i / 100.0});
  for (Vec3d p : {Vec3d{2, 2, 2}, Vec3d{-1, 0.5, 0.5}, Vec3d{0.5, 0.5, 1.5}, Vec3d{0.5, 0.5, -1e-3},
                  Vec3d{1, 1, 1}})
    points.push_back(p);
  std::vector<double> depths;
  const PenetrationStats stats = meter.measure(points, 2, &depths);
  EXPECT_EQ(stats.points, 25);
  EXPECT_EQ(stats.inside, 20);
  EXPECT_DOUBLE_EQ(stats.ratio, 0.8);
  EXPECT_NEAR(stats.max_depth, 0.20, 1e-15);
  EXPECT_NEAR(stats.mean_depth, 0.105, 1e-15);
  EXPECT_NEAR(stats.p95_depth, 0.19, 1e-15);  // nearest rank: ceil(0.95 * 20) = 19th of 20
  for (int i = 0; i < 20; ++i) EXPECT_NEAR(depths[i], (i + 1) / 100.0, 1e-15);
  for (int i = 20; i < 25; ++i) EXPECT_EQ(depths[i], 0.0);

  // 7 inside: ceil(0.95 * 7) = 7, the largest; ratio 7 / 8.
  const PenetrationStats seven = meter.measure(std::vector<Vec3d>{{0.5, 0.5, 0.01},
                                                                  {0.5, 0.5, 0.02},
                                                                  {0.5, 0.5, 0.03},
                                                                  {0.5, 0.5, 0.04},
                                                                  {0.5, 0.5, 0.05},
                                                                  {0.5, 0.5, 0.06},
                                                                  {0.5, 0.5, 0.07},
                                                                  {3, 3, 3}},
                                               1);
  EXPECT_DOUBLE_EQ(seven.ratio, 7.0 / 8.0);
  EXPECT_NEAR(seven.p95_depth, 0.07, 1e-15);

  const PenetrationStats none = meter.measure(std::vector<Vec3d>{{2, 2, 2}, {0, 0, 0}}, 1);
  EXPECT_EQ(none.points, 2);
  EXPECT_EQ(none.inside, 0);
  EXPECT_EQ(none.ratio, 0.0);
  EXPECT_EQ(none.max_depth, 0.0);
  EXPECT_EQ(none.mean_depth, 0.0);
  EXPECT_EQ(none.p95_depth, 0.0);

  const PenetrationStats empty = meter.measure(std::span<const Vec3d>{}, 1, &depths);
  EXPECT_EQ(empty.points, 0);
  EXPECT_EQ(empty.ratio, 0.0);
  EXPECT_TRUE(depths.empty());
}

// ---------------------------------------------------------------------------------------------
// Closedness.

TEST(Closed, CubeIsClosed) {
  const Surface s = cube();
  EXPECT_EQ(why_not_closed(s.triangles, s.vertex_count()), std::nullopt);
  EXPECT_EQ(why_not_closed(icosphere(2, 1.0, {0, 0, 0}).triangles, 162), std::nullopt);
  EXPECT_EQ(why_not_closed(torus(1.0, 0.3, 8, 6).triangles, 48), std::nullopt);
  // Unused vertices are allowed.
  EXPECT_EQ(why_not_closed(s.triangles, 10), std::nullopt);
}

TEST(Closed, CubeWithoutATriangleHasAHole) {
  Surface s = cube();
  s.triangles.pop_back();  // (1, 7, 5): its edges (1, 5), (1, 7), (5, 7) become holes
  EXPECT_EQ(why_not_closed(s.triangles, 8),
            "edge (1, 5) is used by 1 triangle (a hole): triangle 4");
  s.triangles.pop_back();  // the whole +x face: (1, 3), (3, 7), (5, 7), (1, 5) open
  EXPECT_EQ(why_not_closed(s.triangles, 8),
            "edge (1, 3) is used by 1 triangle (a hole): triangle 1");
}

TEST(Closed, FlippedTriangleIsReportedWithTheEdge) {
  Surface s = cube();
  std::swap(s.triangles[0].v[1], s.triangles[0].v[2]);  // (0, 2, 3) -> (0, 3, 2)
  EXPECT_EQ(why_not_closed(s.triangles, 8), "triangles 0 and 9 orient edge (0, 2) the same way");
}

TEST(Closed, NonManifoldEdgeIsReportedWithItsTriangles) {
  Surface s = cube();
  s.triangles.push_back({{0, 1, 7}});  // a third triangle on edge (0, 1)
  EXPECT_EQ(why_not_closed(s.triangles, 8), "edge (0, 1) is used by 3 triangles: 1, 4, 12");
}

TEST(Closed, BadCornersPinchPointsAndEmptyLists) {
  Surface s = cube();
  s.triangles.push_back({{3, 8, 1}});
  EXPECT_EQ(why_not_closed(s.triangles, 8), "triangle 12 has vertex 8, expected one in [0, 8)");
  s.triangles.back() = {{3, 1, 3}};
  EXPECT_EQ(why_not_closed(s.triangles, 8), "triangle 12 repeats vertex 3");
  EXPECT_EQ(why_not_closed({}, 0), "no triangles: an empty surface encloses nothing");

  // A two-sided triangle: every edge used once each way, but nothing inside.
  EXPECT_EQ(why_not_closed(std::vector<Tri>{{{0, 1, 2}}, {{0, 2, 1}}}, 3),
            "triangles 0 and 1 use the same three vertices (a two-sided sheet)");

  // Two cubes that touch at one corner: every edge is fine, vertex 7 is shared by two fans.
  Surface two = cube();
  const Surface other = cube();
  for (int i = 1; i < 8; ++i) two.positions.push_back(other.positions[i] + Vec3d{1, 1, 1});
  for (Tri t : other.triangles) {
    for (int32_t& v : t.v) v = v == 0 ? 7 : v + 7;
    two.triangles.push_back(t);
  }
  const std::optional<std::string> why = why_not_closed(two.triangles, two.vertex_count());
  ASSERT_TRUE(why.has_value());
  EXPECT_EQ(*why,
            "vertex 7 is a pinch point: its triangles form 2 separate fans (triangles 2 and 12 are "
            "in different ones)");
}

// ---------------------------------------------------------------------------------------------
// Clearance at its edge (found by mutation testing: a margin added instead of subtracted kept
// every earlier test passing, the random steps of ClearanceSkipsOnlyPointsProvenOutside never
// landing within 1e-9 of a distance).

TEST(Penetration, ClearanceRemeasuresAPointThatMovedJustPastItsDistance) {
  // A point 1 below the unit cube's bottom face, then moved straight up by 1 + 5e-10: it is
  // now 5e-10 inside (the bottom face is its closest), a depth worked out by hand. Its movement
  // exceeds its distance, so the clearance must not skip it, however small the excess.
  const PenetrationMeter meter = meter_for(cube());
  Clearance clearance;
  const double z = 5e-10;
  std::vector<double> depths;
  EXPECT_EQ(meter.measure(std::vector<Vec3d>{{0.5, 0.5, -1.0}}, clearance, 1, &depths).inside, 0);
  EXPECT_EQ(depths[0], 0.0);
  const PenetrationStats moved =
      meter.measure(std::vector<Vec3d>{{0.5, 0.5, z}}, clearance, 1, &depths);
  EXPECT_EQ(moved.proven_outside, 0);
  EXPECT_EQ(moved.inside, 1);
  EXPECT_DOUBLE_EQ(depths[0], z);

  // The same with the obstacle's travel making up most of it: the cube moves down by 0.5 and
  // the point up by 0.5 + 5e-10, ending 5e-10 above the moved bottom face (z = -0.5).
  Surface s = cube();
  PenetrationMeter moving = meter_for(s);
  Clearance second;
  EXPECT_EQ(moving.measure(std::vector<Vec3d>{{0.5, 0.5, -1.0}}, second, 1, &depths).inside, 0);
  for (Vec3d& v : s.positions) v = v + Vec3d{0.0, 0.0, -0.5};
  moving.update_positions(s.positions, 1);
  EXPECT_EQ(moving.travel(), 0.5);
  const PenetrationStats both =
      moving.measure(std::vector<Vec3d>{{0.5, 0.5, -0.5 + z}}, second, 1, &depths);
  EXPECT_EQ(both.proven_outside, 0);
  EXPECT_EQ(both.inside, 1);
  EXPECT_NEAR(depths[0], z, 1e-16);
}

}  // namespace
}  // namespace snag::measure
