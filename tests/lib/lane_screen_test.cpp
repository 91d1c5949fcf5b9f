// LaneScreen (the CPU walks' rejection by sides and test of segments apart, several lanes a
// vector) against the pair-by-pair tests it stands for, pair_passes_sides and
// test_pair_given_shared, on pairs that share no vertex: random triangles,
// triangles on one slanted plane up to rounding (sides within a few units in the last place of
// zero, on both sides of the filter's bound), exact zeros (integer coordinates, repeated points
// under other ids), coordinates whose differences underflow, and a query below the bound's
// range. Groups of 8 are also run compiled for AVX2, as the walks run them, where the CPU has it.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <random>
#include <vector>

#include "snag/detect/lane_screen.h"

namespace snag::test {
namespace {

#if defined(__x86_64__) && defined(__GNUC__)
/// LaneScreen<8>::settle compiled for AVX2 and inlined whole, as cpu_backend.cpp's
/// walk_group_avx2 runs it (the test binary itself is built for the baseline).
[[gnu::target("avx2"), gnu::flatten]] detect::LaneScreen<8>::Settled settle_avx2(
    const detect::LaneScreen<8>& screen, const geom::Vec3d* positions,
    const geom::PlaneCoefficients& plane, const geom::Tri& xt, uint32_t wanted) {
  return screen.settle(positions, plane, xt, wanted);
}
bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2");
}
#else
detect::LaneScreen<8>::Settled settle_avx2(const detect::LaneScreen<8>&, const geom::Vec3d*,
                                           const geom::PlaneCoefficients&, const geom::Tri&,
                                           uint32_t) {
  return {};
}
bool cpu_has_avx2() {
  return false;
}
#endif

/// A frame of loose triangles: its positions, triangles and their planes, each triangle
/// representing a random subset of its own three edges.
struct LooseTriangles {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
  std::vector<std::array<int32_t, 3>> triangle_edges;
  std::vector<uint8_t> owned_edges;
  std::vector<geom::PlaneCoefficients> planes;

  void add(geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) {
    const int32_t first = static_cast<int32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    triangles.push_back({{first, first + 1, first + 2}});
    triangle_edges.push_back({first, first + 1, first + 2});
    owned_edges.push_back(static_cast<uint8_t>(owned_edges.size() * 5 % 8));
  }
  detect::FrameView frame() {
    planes.clear();
    for (const geom::Tri& t : triangles)
      planes.push_back(detect::triangle_plane(positions.data(), t));
    return {positions.data(), planes.data(), nullptr};
  }
  detect::TopologyView topology() const {
    detect::TopologyView view{};
    view.triangles = triangles.data();
    view.triangle_edges = triangle_edges.data();
    view.owned_edges = owned_edges.data();
    view.triangle_count = static_cast<int32_t>(triangles.size());
    view.edge_count = 3 * view.triangle_count;
    return view;
  }
};

/// What the pair test reports, counted.
struct CountingSink {
  int hits = 0, uncertain_tests = 0, misses = 0, duplicates = 0;
  void hit(int32_t, int32_t) { ++hits; }
  void uncertain(int32_t, int32_t) { ++uncertain_tests; }
  void miss() { ++misses; }
  void duplicate(int32_t, int32_t) { ++duplicates; }
};

/// straddling_edge_hits' answer "apart" for (t, x), sharing no vertex, rebuilt from the library's
/// scalar pieces with the filter alone (no plane_side_rare, whose exact zeros the screen leaves
/// to the pair test): both triangles' sides strict and not all alike, then the two orders of the
/// segments' ends, certain, and apart.
bool filter_says_apart(const detect::FrameView& frame, int32_t t, const geom::Tri& tt, int32_t x,
                       const geom::Tri& xt) {
  geom::Sign st[3], sx[3];
  detect::sides_against(frame.positions, frame.planes[x], tt, 0, xt, st);
  detect::sides_against(frame.positions, frame.planes[t], xt, 0, tt, sx);
  if (!geom::strict_sides(st) || !geom::strict_sides(sx)) return false;
  if (detect::separated(st, 0) || detect::separated(sx, 0)) return false;
  const int fl = geom::lone_corner(st), xl = geom::lone_corner(sx);
  const geom::Vec3d* p = frame.positions;
  const geom::Vec3d f0 = p[tt.v[fl]], f1 = p[tt.v[(fl + 1) % 3]], f2 = p[tt.v[(fl + 2) % 3]];
  const geom::Vec3d x0 = p[xt.v[xl]], x1 = p[xt.v[(xl + 1) % 3]], x2 = p[xt.v[(xl + 2) % 3]];
  const bool a_positive = st[fl] == geom::Sign::positive;
  const bool b_positive = sx[xl] == geom::Sign::positive;
  // The sign of J_j - I_i along the planes' line, from plane (f0, f_i, x0) and point x_j.
  auto order = [&](geom::Vec3d fi, geom::Vec3d xj) {
    double perm;
    const geom::Sign s =
        geom::plane_side_filter(geom::PlaneCoefficients::of(f0, fi, x0), f0, xj, perm);
    return a_positive != b_positive ? geom::negate(s) : s;
  };
  const geom::Vec3d f_low = a_positive ? f2 : f1, f_high = a_positive ? f1 : f2;
  const geom::Vec3d x_low = b_positive ? x1 : x2, x_high = b_positive ? x2 : x1;
  const geom::Sign above_low = order(f_low, x_high);
  if (above_low == geom::Sign::uncertain) return false;
  return above_low == geom::Sign::negative || order(f_high, x_low) == geom::Sign::positive;
}

/// How many wanted pairs the screen settled, of each kind.
struct SettledCounts {
  int64_t separated = 0, apart = 0, left = 0;
};

/// Every triangle in turn as x, against groups of W of the others (lanes filled in order, the
/// last group short when the count does not divide), with one lane of each group left out of
/// `wanted` at random. For each wanted lane: separated exactly when the pair-by-pair rejection
/// (pair_passes_sides) says so; apart exactly when filter_says_apart does, and only where the
/// whole pair test (test_pair_given_shared) reports a miss for every edge either triangle
/// represents and nothing else. No other lane's
/// bit set; groups of 8 compiled for AVX2 give the same bits.
template <int W>
SettledCounts expect_same_as_pair_by_pair(LooseTriangles& loose, std::mt19937& rng) {
  const detect::FrameView frame = loose.frame();
  const detect::TopologyView topo = loose.topology();
  const int32_t n = static_cast<int32_t>(loose.triangles.size());
  SettledCounts counts;
  for (int32_t x = 0; x < n; ++x) {
    std::vector<int32_t> others;
    for (int32_t t = 0; t < n; ++t)
      if (t != x) others.push_back(t);
    std::shuffle(others.begin(), others.end(), rng);
    for (size_t first = 0; first < others.size(); first += W) {
      int32_t lane_triangle[W] = {};
      const int members = static_cast<int>(std::min<size_t>(W, others.size() - first));
      for (int lane = 0; lane < members; ++lane) lane_triangle[lane] = others[first + lane];
      const detect::LaneScreen<W> screen(lane_triangle, members, frame, topo.triangles, 0);
      uint32_t wanted = (1u << members) - 1u;
      wanted &= ~(1u << std::uniform_int_distribution<int>(0, W)(rng));
      const auto settled =
          screen.settle(frame.positions, frame.planes[x], topo.triangles[x], wanted);
      if constexpr (W == 8) {
        if (cpu_has_avx2()) {
          const auto avx2 =
              settle_avx2(screen, frame.positions, frame.planes[x], topo.triangles[x], wanted);
          EXPECT_EQ(avx2.separated, settled.separated) << "AVX2 against the baseline, x " << x;
          EXPECT_EQ(avx2.apart, settled.apart) << "AVX2 against the baseline, x " << x;
        }
      }
      EXPECT_EQ((settled.separated | settled.apart) & ~wanted, 0u) << "lanes not wanted";
      EXPECT_EQ(settled.separated & settled.apart, 0u) << "separated and apart";
      for (int lane = 0; lane < members; ++lane) {
        if (!(wanted & (1u << lane))) continue;
        const int32_t t = lane_triangle[lane];
        const bool separated = !detect::pair_passes_sides(frame, topo, t, x, 0, 0);
        EXPECT_EQ((settled.separated >> lane) & 1u, separated ? 1u : 0u)
            << "W " << W << ", triangle " << t << " against " << x;
        if (!separated)
          EXPECT_EQ((settled.apart >> lane) & 1u,
                    filter_says_apart(frame, t, topo.triangles[t], x, topo.triangles[x]) ? 1u : 0u)
              << "apart: W " << W << ", triangle " << t << " against " << x;
        if ((settled.apart >> lane) & 1u) {
          CountingSink sink;
          detect::test_pair_given_shared(frame, topo, t, x, 0, 0, sink);
          EXPECT_EQ(sink.hits + sink.uncertain_tests + sink.duplicates, 0)
              << "apart, but the pair test reports more than misses: W " << W << ", triangle " << t
              << " against " << x;
          EXPECT_EQ(sink.misses, std::popcount(topo.owned_edges[t] & 7u) +
                                     std::popcount(topo.owned_edges[x] & 7u))
              << "W " << W << ", triangle " << t << " against " << x;
        }
        if (::testing::Test::HasFailure()) return counts;
        counts.separated += separated;
        counts.apart += (settled.apart >> lane) & 1u;
        counts.left += !separated && !((settled.apart >> lane) & 1u);
      }
    }
  }
  return counts;
}

template <int W>
void check_all_cases() {
  std::mt19937 rng(2026);
  {  // Random triangles in a unit cube: most pairs separated, some straddling.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    auto point = [&] { return geom::Vec3d{coord(rng), coord(rng), coord(rng)}; };
    for (int i = 0; i < 120; ++i) loose.add(point(), point(), point());
    // Every outcome occurs: separated, apart, and left to the pair test (some of those meet).
    const SettledCounts counts = expect_same_as_pair_by_pair<W>(loose, rng);
    EXPECT_GT(counts.separated, 0);
    EXPECT_GT(counts.apart, 0);
    EXPECT_GT(counts.left, 0);
  }
  {  // Small integers: exact zeros everywhere (coplanar corners, points on planes), which the
     // filter leaves uncertain and which must never count as separating.
    LooseTriangles loose;
    std::uniform_int_distribution<int> coord(-2, 2);
    auto point = [&] {
      return geom::Vec3d{double(coord(rng)), double(coord(rng)), 0.5 * coord(rng)};
    };
    for (int i = 0; i < 120; ++i) loose.add(point(), point(), point());
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // On one slanted plane up to rounding: most sides are a few units in the last place from
     // zero, some certified and some not (in the two side stages, a bound off by a tenth, a sum
     // in another order or another origin fails here).
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    for (int plane = 0; plane < 30; ++plane) {
      LooseTriangles loose;
      const double a = coord(rng), b = coord(rng), d = coord(rng);
      auto point = [&] {
        const double x = coord(rng), y = coord(rng);
        return geom::Vec3d{x, y, a * x + b * y + d};
      };
      for (int i = 0; i < 40; ++i) loose.add(point(), point(), point());
      expect_same_as_pair_by_pair<W>(loose, rng);
    }
  }
  {  // A flat sheet with small lifts, and repeated positions under other ids (an unwelded
     // seam): clear sides and exact zeros.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(0.0, 1.0), lift(-1e-15, 1e-15);
    for (int i = 0; i < 60; ++i) {
      const geom::Vec3d a{coord(rng), coord(rng), lift(rng)};
      const geom::Vec3d b{a.x + 0.1, a.y, lift(rng)}, c{a.x, a.y + 0.1, -0.0};
      loose.add(a, b, c);
      loose.add(b, c, geom::Vec3d{a.x + 0.1, a.y + 0.1, lift(rng)});
    }
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // Tiny and huge coordinates: differences that underflow make a plane's queries uncertain
     // (a NaN permanent), and products near the top of the range.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    for (double scale : {1e-160, 1e-300, 1e150, 1.0}) {
      auto point = [&] { return geom::Vec3d{scale * coord(rng), scale * coord(rng), coord(rng)}; };
      for (int i = 0; i < 30; ++i) loose.add(point(), point(), point());
    }
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // One corner of each triangle on x = 0 or x = 1e-310: the two lone corners of a pair often
     // differ by a subnormal, a difference whose products may underflow (not safe_difference),
     // which leaves the segments' order uncertain however clear it looks.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    std::bernoulli_distribution tiny(0.5);
    auto point = [&] { return geom::Vec3d{coord(rng), coord(rng), coord(rng)}; };
    for (int i = 0; i < 160; ++i) {
      geom::Vec3d snapped = point();
      snapped.x = tiny(rng) ? 1e-310 : 0.0;
      loose.add(snapped, point(), point());
    }
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // x's edge through a point of t's edge, up to rounding: the segments' ends nearly meet, so
     // their order is near zero, certified or not.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0), along(0.0, 1.0);
    auto point = [&] { return geom::Vec3d{coord(rng), coord(rng), coord(rng)}; };
    for (int i = 0; i < 60; ++i) {
      const geom::Vec3d a = point(), b = point(), c = point(), e = point();
      const double s = along(rng);
      const geom::Vec3d on_edge{a.x + s * (b.x - a.x), a.y + s * (b.y - a.y),
                                a.z + s * (b.z - a.z)};
      loose.add(a, b, c);
      loose.add({on_edge.x + e.x, on_edge.y + e.y, on_edge.z + e.z},
                {on_edge.x - e.x, on_edge.y - e.y, on_edge.z - e.z}, point());
    }
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // Two corners of each triangle a subnormal apart in x (its own plane's rows stay safe,
     // measured from corner 0): the segments' order from a lone corner 1 or 2 has a row whose
     // products may underflow.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    for (int i = 0; i < 160; ++i)
      loose.add({coord(rng), coord(rng), coord(rng)}, {0.0, coord(rng), coord(rng)},
                {1e-310, coord(rng), coord(rng)});
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
  {  // A corner within 2^-900 of the other's plane origin: the query's permanent is below the
     // bound's range, so that side is uncertain however clear its sign looks.
    LooseTriangles loose;
    loose.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
    for (int i = 0; i < 2 * W; ++i)
      loose.add({1e-280, 1e-280, 1e-290}, {0.3, 0.2, 1.0 + i}, {0.2, 0.3, 2.0 + i});
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
}

TEST(LaneScreen, FourLanesAnswerAsThePairByPairTests) {
  check_all_cases<4>();
}

TEST(LaneScreen, EightLanesAnswerAsThePairByPairTests) {
  check_all_cases<8>();
}

}  // namespace
}  // namespace snag::test
