// snag against CGAL: the exact provider against the filter, the pairs against CGAL's
// self_intersections (and its rules applied pair by pair on soups it cannot hold), and the
// crossing/touching kinds against CGAL's exact intersection construction.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "../../validators/src/cgal_predicates.h"
#include "snag/detect/checker.h"
#include "snag/detect/cpu_backend.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/weld.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"
#include "test_paths.h"

namespace snag::validators {
namespace {

using Pairs = std::vector<std::pair<int32_t, int32_t>>;

detect::FrameResult snag_check(std::span<const geom::Vec3d> positions,
                               std::span<const geom::Tri> triangles, int threads = 2) {
  detect::Checker checker(detect::make_cpu_backend(threads), make_cgal_resolver());
  checker.set_triangles(triangles, static_cast<int32_t>(positions.size()));
  return checker.check(positions);
}

void expect_kinds_match(std::span<const geom::Vec3d> positions,
                        std::span<const geom::Tri> triangles,
                        const std::vector<detect::FacePair>& pairs, const std::string& what) {
  for (const auto& p : pairs)
    ASSERT_EQ(p.kind, cgal_pair_kind(positions, triangles[p.a], triangles[p.b]))
        << what << ": pair " << p.a << "," << p.b;
}

struct Soup {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
};

/// Lattice soups scaled and offset by non-representable amounts: coordinates are doubles of
/// all sizes, contacts are exact, and the filter is uncertain about many of them.
Soup lattice_soup(int32_t n, int range, uint32_t seed, double scale, double offset) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(0, range);
  std::uniform_int_distribution<int32_t> pick(0, 2 * n - 1);
  Soup soup;
  for (int32_t v = 0; v < 2 * n; ++v)
    soup.positions.push_back(
        {coord(rng) * scale + offset, coord(rng) * scale - offset, coord(rng) * scale});
  for (int32_t t = 0; t < n; ++t) soup.triangles.push_back({{pick(rng), pick(rng), pick(rng)}});
  return soup;
}

TEST(ExactProvider, AgreesWithTheFilterWheneverTheFilterIsCertain) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  std::uniform_int_distribution<int> ulps(-3, 3);
  std::vector<geom::Vec3d> p(4);
  int uncertain = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    for (int k = 0; k < 3; ++k) p[k] = {coord(rng), coord(rng), coord(rng)};
    // The fourth point on the plane of the others, then moved a few ulps: near-degenerate.
    const double s = coord(rng), t = coord(rng);
    p[3] = p[0] + s * (p[1] - p[0]) + t * (p[2] - p[0]);
    p[3].z = std::nextafter(p[3].z, p[3].z + ulps(rng));
    const geom::FilteredPredicates filtered{p.data()};
    const CgalPredicates exact{p.data()};
    const geom::Sign f = filtered.orient3d(0, 1, 2, 3);
    if (f == geom::Sign::uncertain) {
      ++uncertain;
      continue;
    }
    ASSERT_EQ(f, exact.orient3d(0, 1, 2, 3)) << "trial " << trial << " (seed 2026)";
    for (int axis = 0; axis < 3; ++axis) {
      const geom::Sign f2 = filtered.orient2d(0, 1, 3, axis);
      if (f2 != geom::Sign::uncertain)
        ASSERT_EQ(f2, exact.orient2d(0, 1, 3, axis)) << "trial " << trial;
    }
  }
  EXPECT_GT(uncertain, 1000) << "the near-degenerate inputs should defeat the filter often";
}

TEST(CgalAgreement, LatticeSoupsPairForPairWithExactKinds) {
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const double scale = seed % 2 ? 0.1 : 3.0;  // 0.1 is not a binary fraction
    const Soup soup = lattice_soup(60 + static_cast<int32_t>(seed % 7) * 20, 4, seed, scale,
                                   seed % 3 ? 0.7 : 1e6);
    const Pairs expected = cgal_soup_self_intersections(soup.positions, soup.triangles);
    for (int threads : {1, 2}) {
      const detect::FrameResult result = snag_check(soup.positions, soup.triangles, threads);
      ASSERT_EQ(pair_ids(result.pairs), expected) << "seed " << seed << " threads " << threads;
      expect_kinds_match(soup.positions, soup.triangles, result.pairs,
                         "seed " + std::to_string(seed));
    }
  }
}

TEST(CgalAgreement, SampleSequenceMatchesSelfIntersections) {
  const auto dir = test::source_dir() / "samples" / "drape";
  if (!std::filesystem::is_directory(dir))
    GTEST_SKIP() << "no samples/drape under " << test::source_dir();
  int frames = 0, with_pairs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".obj") continue;
    const mesh::Mesh mesh = io::read_mesh(entry.path());
    const detect::FrameResult result = snag_check(mesh.positions, mesh.triangles);
    ASSERT_EQ(pair_ids(result.pairs), cgal_self_intersections(mesh.positions, mesh.triangles))
        << entry.path();
    expect_kinds_match(mesh.positions, mesh.triangles, result.pairs, entry.path().string());
    ++frames;
    with_pairs += !result.pairs.empty();
  }
  EXPECT_GE(frames, 10);
  EXPECT_GE(with_pairs, 5);
}

TEST(CgalReference, SequenceReusingTheMeshMatchesFreshMeshes) {
  const auto dir = test::source_dir() / "samples" / "drape";
  if (!std::filesystem::is_directory(dir))
    GTEST_SKIP() << "no samples/drape under " << test::source_dir();
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".obj") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 2u);
  const mesh::Mesh first = io::read_mesh(files.front());
  CgalSequence sequence(first.positions, first.triangles);
  size_t total = 0;
  for (const auto& file : files) {
    const mesh::Mesh frame = io::read_mesh(file);
    sequence.set_positions(frame.positions);
    const Pairs pairs = sequence.self_intersections();
    ASSERT_EQ(pairs, cgal_self_intersections(frame.positions, frame.triangles)) << file;
    total += pairs.size();
  }
  EXPECT_GT(total, 0u);
}

struct DataFile {
  const char* path;
  size_t triangles;
  size_t cgal_pairs;
};

class DataAgreement : public ::testing::TestWithParam<DataFile> {};

TEST_P(DataAgreement, MatchesCgalPairForPairAndTheReferenceCount) {
  const auto data = test::data_dir();
  if (data.empty())
    GTEST_SKIP()
        << "../shared/data is absent (set SNAG_DATA_DIR): skipping the real-data agreement";
  const DataFile& file = GetParam();
  mesh::Mesh mesh = io::read_mesh(data / file.path);
  ASSERT_EQ(mesh.triangles.size(), file.triangles);
  if (std::filesystem::path(file.path).extension() == ".stl") {
    // STL is a triangle soup: weld exactly coincident corners first (the reference counts
    // are after welding), as `snag check --weld 0` does.
    mesh.triangles =
        mesh::welded_triangles(mesh.triangles, mesh::weld_representatives(mesh.positions, 0.0));
  }
  const detect::FrameResult result = snag_check(mesh.positions, mesh.triangles);
  Pairs expected;
  try {
    expected = cgal_self_intersections(mesh.positions, mesh.triangles);
  } catch (const InternalError&) {
    expected = cgal_soup_self_intersections(mesh.positions, mesh.triangles);
  }
  EXPECT_EQ(result.pairs.size(), file.cgal_pairs) << "reference count of ../shared/data/README.md";
  ASSERT_EQ(pair_ids(result.pairs), expected);
  EXPECT_TRUE(result.degenerate.empty()) << result.degenerate.size() << " degenerate faces";
  if (result.pairs.size() < 20000)
    expect_kinds_match(mesh.positions, mesh.triangles, result.pairs, file.path);
}

INSTANTIATE_TEST_SUITE_P(
    SharedData, DataAgreement,
    ::testing::Values(DataFile{"scalable-ccd/cloth-ball/cloth_ball92.ply", 92230, 63602},
                      DataFile{"scalable-ccd/cloth-ball/cloth_ball93.ply", 92230, 99872},
                      DataFile{"scalable-ccd/cloth-funnel/227.ply", 18484, 309},
                      DataFile{"scalable-ccd/cloth-funnel/228.ply", 18484, 382},
                      DataFile{"scalable-ccd/rod-twist/3036.ply", 79864, 0},
                      DataFile{"scalable-ccd/rod-twist/3037.ply", 79864, 0},
                      DataFile{"scalable-ccd/armadillo-rollers/326.ply", 24242, 0},
                      DataFile{"scalable-ccd/armadillo-rollers/327.ply", 24242, 0},
                      DataFile{"scalable-ccd/n-body-simulation/balls16_18.ply", 146480, 4916},
                      DataFile{"scalable-ccd/n-body-simulation/balls16_19.ply", 146480, 4401},
                      DataFile{"ipc-toolkit/thick-cloth/t0.ply", 404, 0},
                      DataFile{"ipc-toolkit/thick-cloth/t1.ply", 404, 46},
                      DataFile{"ipc-toolkit/two-cubes-far.ply", 480, 0},
                      DataFile{"ipc-toolkit/two-cubes-close.ply", 480, 0},
                      DataFile{"ipc-toolkit/two-cubes-intersecting.ply", 480, 96},
                      DataFile{"ipc-toolkit/bunny.ply", 5002, 0},
                      DataFile{"ipc-toolkit/cube.ply", 12, 0},
                      DataFile{"ipc-toolkit/height-field.ply", 4904, 0},
                      DataFile{"arrangements/three_cubes.stl", 36, 41},
                      DataFile{"arrangements/two_spheres.stl", 1600, 132}),
    [](const ::testing::TestParamInfo<DataFile>& info) {
      std::string name = info.param.path;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return name;
    });

}  // namespace
}  // namespace snag::validators
