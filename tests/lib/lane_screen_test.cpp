// LaneScreen (the CPU walks' rejection by sides, several lanes a vector) against the pair-by-pair
// rejection it replaces, pair_passes_sides, on pairs that share no vertex: random triangles,
// triangles on one slanted plane up to rounding (sides within a few units in the last place of
// zero, on both sides of the filter's bound), exact zeros (integer coordinates, repeated points
// under other ids), coordinates whose differences underflow, and a query below the bound's
// range. Groups of 8 are also run compiled for AVX2, as the walks run them, where the CPU has it.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "snag/detect/lane_screen.h"

namespace snag::test {
namespace {

#if defined(__x86_64__) && defined(__GNUC__)
/// LaneScreen<8>::separated compiled for AVX2 and inlined whole, as cpu_backend.cpp's
/// walk_group_avx2 runs it (the test binary itself is built for the baseline).
[[gnu::target("avx2"), gnu::flatten]] uint32_t separated_avx2(const detect::LaneScreen<8>& screen,
                                                              const geom::Vec3d* positions,
                                                              const geom::PlaneCoefficients& plane,
                                                              const geom::Tri& xt,
                                                              uint32_t wanted) {
  return screen.separated(positions, plane, xt, wanted);
}
bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2");
}
#else
uint32_t separated_avx2(const detect::LaneScreen<8>&, const geom::Vec3d*,
                        const geom::PlaneCoefficients&, const geom::Tri&, uint32_t) {
  return 0;
}
bool cpu_has_avx2() {
  return false;
}
#endif

/// A frame of loose triangles: its positions, triangles and their planes.
struct LooseTriangles {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
  std::vector<geom::PlaneCoefficients> planes;

  void add(geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) {
    const int32_t first = static_cast<int32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    triangles.push_back({{first, first + 1, first + 2}});
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
    view.triangle_count = static_cast<int32_t>(triangles.size());
    return view;
  }
};

/// Every triangle in turn as x, against groups of W of the others (lanes filled in order, the
/// last group short when the count does not divide), with one lane of each group left out of
/// `wanted` at random: each wanted lane's bit must be what the pair-by-pair test answers, and
/// no other lane's bit set. Returns how many wanted pairs were separated.
template <int W>
int64_t expect_same_as_pair_by_pair(LooseTriangles& loose, std::mt19937& rng) {
  const detect::FrameView frame = loose.frame();
  const detect::TopologyView topo = loose.topology();
  const int32_t n = static_cast<int32_t>(loose.triangles.size());
  int64_t separated_count = 0;
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
      const uint32_t bits =
          screen.separated(frame.positions, frame.planes[x], topo.triangles[x], wanted);
      if constexpr (W == 8) {
        if (cpu_has_avx2())
          EXPECT_EQ(
              separated_avx2(screen, frame.positions, frame.planes[x], topo.triangles[x], wanted),
              bits)
              << "AVX2 against the baseline build, x " << x;
      }
      EXPECT_EQ(bits & ~wanted, 0u) << "lanes not wanted";
      for (int lane = 0; lane < members; ++lane) {
        if (!(wanted & (1u << lane))) continue;
        const int32_t t = lane_triangle[lane];
        const bool expected = !detect::pair_passes_sides(frame, topo, t, x, 0, 0);
        EXPECT_EQ((bits >> lane) & 1u, expected ? 1u : 0u)
            << "W " << W << ", triangle " << t << " against " << x;
        if (::testing::Test::HasFailure()) return separated_count;
        separated_count += expected;
      }
    }
  }
  return separated_count;
}

template <int W>
void check_all_cases() {
  std::mt19937 rng(2026);
  {  // Random triangles in a unit cube: most pairs separated, some straddling.
    LooseTriangles loose;
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    auto point = [&] { return geom::Vec3d{coord(rng), coord(rng), coord(rng)}; };
    for (int i = 0; i < 120; ++i) loose.add(point(), point(), point());
    const int64_t separated = expect_same_as_pair_by_pair<W>(loose, rng);
    EXPECT_GT(separated, 0);
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
     // zero, some certified and some not (a bound off by a tenth, a sum in another order or
     // another origin fails here).
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
  {  // A corner within 2^-900 of the other's plane origin: the query's permanent is below the
     // bound's range, so that side is uncertain however clear its sign looks.
    LooseTriangles loose;
    loose.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
    for (int i = 0; i < 2 * W; ++i)
      loose.add({1e-280, 1e-280, 1e-290}, {0.3, 0.2, 1.0 + i}, {0.2, 0.3, 2.0 + i});
    expect_same_as_pair_by_pair<W>(loose, rng);
  }
}

TEST(LaneScreen, FourLanesAnswerAsThePairByPairRejection) {
  check_all_cases<4>();
}

TEST(LaneScreen, EightLanesAnswerAsThePairByPairRejection) {
  check_all_cases<8>();
}

}  // namespace
}  // namespace snag::test
