// The CUDA backend against the CPU backend and brute force: the same tree (permutation and
// boxes, bit for bit), the same filtered frames (pairs, certain kinds, uncertain tests, counts),
// the same checked frames, on hand-built cases, lattice soups, folded grids, deformed sequences,
// frames with more results than the buffers first hold, and the shared data files.
// Without a GPU every test skips with a loud message (CI has nvcc but no GPU).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>

#include "detect_cases.h"
#include "require_gpu.h"
#include "scene_cases.h"
#include "snag/bvh/tree.h"
#include "snag/cuda/cuda_backend.h"
#include "snag/detect/cpu_backend.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "test_paths.h"

namespace snag::test {
namespace {

std::unique_ptr<cuda::CudaBackend> gpu_backend() {
  std::unique_ptr<detect::Backend> backend = cuda::make_cuda_backend(0);
  auto* gpu = dynamic_cast<cuda::CudaBackend*>(backend.get());
  if (!gpu) throw std::logic_error("make_cuda_backend did not make a cuda::CudaBackend");
  backend.release();
  return std::unique_ptr<cuda::CudaBackend>(gpu);
}

/// A CPU backend (two threads) and a GPU backend on one topology, which must outlive them (the
/// backends hold it by reference); the GPU's result buffers start at `capacity` when it is given,
/// so that their growth is exercised.
struct BothBackends {
  std::unique_ptr<detect::Backend> cpu;
  std::unique_ptr<cuda::CudaBackend> gpu;
};
BothBackends both_backends(const detect::Topology& topology, int64_t capacity = 0) {
  BothBackends both{detect::make_cpu_backend(2), gpu_backend()};
  if (capacity > 0) both.gpu->set_result_capacity(capacity);
  both.cpu->set_topology(topology);
  both.gpu->set_topology(topology);
  return both;
}

/// Runs one frame through a backend the way the checker does, filter only.
struct Filtered {
  detect::DegeneracyScan scan;
  double quality = 0;
  detect::FilteredFrame frame;
};

Filtered filtered(detect::Backend& backend, std::span<const geom::Vec3d> positions, bool build,
                  detect::FilterUse use = detect::FilterUse::certify) {
  Filtered f;
  backend.set_positions(positions);
  f.scan = backend.scan_degenerate();
  if (build)
    backend.build();
  else
    backend.refit();
  f.quality = backend.tree_quality();
  f.frame = backend.detect(f.scan.degenerate, use);
  return f;
}

void expect_same_frame(const detect::FilteredFrame& cpu, const detect::FilteredFrame& gpu,
                       const std::string& what) {
  EXPECT_EQ(cpu.pairs, gpu.pairs) << what;
  EXPECT_EQ(cpu.kind_certain, gpu.kind_certain) << what;
  EXPECT_EQ(cpu.uncertain, gpu.uncertain) << what;
  EXPECT_EQ(cpu.candidate_pairs, gpu.candidate_pairs) << what;
  EXPECT_EQ(cpu.filtered_tests, gpu.filtered_tests) << what;
}

void expect_same(const Filtered& cpu, const Filtered& gpu, const std::string& what) {
  EXPECT_EQ(cpu.scan.degenerate, gpu.scan.degenerate) << what;
  EXPECT_EQ(cpu.scan.uncertain, gpu.scan.uncertain) << what;
  EXPECT_EQ(cpu.quality, gpu.quality) << what;  // bit for bit
  expect_same_frame(cpu.frame, gpu.frame, what);
}

/// Both backends on one mesh, one frame, from a fresh build.
void expect_same_filtered(const SmallMesh& mesh, const std::string& what, int64_t capacity = 0,
                          detect::FilterUse use = detect::FilterUse::certify) {
  const detect::Topology topology =
      detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  auto [cpu, gpu] = both_backends(topology, capacity);
  expect_same(filtered(*cpu, mesh.positions, true, use), filtered(*gpu, mesh.positions, true, use),
              what);
}

detect::FrameResult check_on_gpu(const SmallMesh& mesh) {
  detect::Checker checker(gpu_backend(), std::make_shared<IntegerResolver>());
  checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  return checker.check(mesh.positions);
}

TEST(CudaTree, SameTreeAsTheCpuForManySizes) {
  SNAG_REQUIRE_GPU();
  auto gpu = gpu_backend();
  std::vector<int32_t> sizes;
  for (int32_t n = 1; n <= 300; ++n) sizes.push_back(n);
  for (int32_t n : {511, 512, 513, 1000, 1023, 1024, 1025, 4097, 10000, 65537, 200000})
    sizes.push_back(n);
  for (int32_t n : sizes) {
    const uint32_t seed = 7000 + static_cast<uint32_t>(n);
    // Coarse coordinates: many equal centroid coordinates, so ties are broken by id often.
    SmallMesh soup = random_soup(n, seed, 0.5);
    if (n % 3 == 0)
      for (auto& p : soup.positions)
        p = {std::round(p.x), std::round(p.y * 2) / 2, std::round(p.z)};
    if (n % 5 == 0)
      for (auto& p : soup.positions) p.x = -p.x;  // negative coordinates, -0 among them
    if (n % 7 == 0)  // collapsed triangles, whose leaves get the empty box
      collapse_soup_triangles(soup, 4, 1, {5.0, 5.0, 5.0});
    const mesh::MeshView view = mesh::view_of(soup.positions, soup.triangles);
    bvh::Tree cpu_tree;
    cpu_tree.build(view, 2);
    const detect::Topology topology =
        detect::make_topology(soup.triangles, static_cast<int32_t>(soup.positions.size()));
    gpu->set_topology(topology);
    gpu->set_positions(soup.positions);
    gpu->build();
    ASSERT_EQ(gpu->triangle_order(), cpu_tree.triangle_at()) << "n=" << n << " seed=" << seed;
    const std::vector<geom::Box3f> boxes = gpu->node_boxes();
    ASSERT_EQ(boxes.size(), cpu_tree.boxes().size());
    ASSERT_EQ(
        std::memcmp(boxes.data(), cpu_tree.boxes().data(), boxes.size() * sizeof(geom::Box3f)), 0)
        << "n=" << n;
    ASSERT_EQ(gpu->tree_quality(), cpu_tree.quality()) << "n=" << n;
  }
}

TEST(CudaTree, RefitStrategiesGiveTheCpuBoxes) {
  SNAG_REQUIRE_GPU();
  // Up to 256 leaves one block fits every level (one warp up to 64, then two or four); then
  // the last block's first warp takes the blocks' roots (2 to 256 of them: one a lane up to
  // 8,192 leaves, two, four, then eight from 32,769), and past 2^16 leaves the whole block
  // merges the widest levels above them first (cuda/src/device_tree.cu).
  for (int32_t n : {1,   2,    3,    5,    20,   40,    77,    128,   129,   257,   512,
                    513, 1000, 1500, 3000, 5000, 10000, 20000, 33333, 70000, 300001}) {
    SmallMesh soup = random_soup(n, 11 + static_cast<uint32_t>(n), 0.3);
    const detect::Topology topology =
        detect::make_topology(soup.triangles, static_cast<int32_t>(soup.positions.size()));
    bvh::Tree cpu_tree;
    cpu_tree.build(mesh::view_of(soup.positions, soup.triangles), 2);
    for (bool level_by_level : {false, true}) {
      auto gpu = gpu_backend();
      gpu->set_level_by_level_refit(level_by_level);
      gpu->set_topology(topology);
      gpu->set_positions(soup.positions);
      gpu->build();
      SmallMesh moved = soup;
      std::mt19937 rng(5 + static_cast<uint32_t>(n));
      std::uniform_real_distribution<double> move(-2.0, 2.0);
      for (int frame = 0; frame < 3; ++frame) {
        for (auto& p : moved.positions) p = p + geom::Vec3d{move(rng), move(rng), move(rng)};
        // Frame 1 collapses some triangles (empty leaf boxes); frame 2 moves them apart again.
        if (frame == 1) collapse_soup_triangles(moved, 3, frame, {1.0, 2.0, 3.0});
        bvh::Tree cpu_copy = cpu_tree;
        cpu_copy.refit(mesh::view_of(moved.positions, moved.triangles), 2);
        gpu->set_positions(moved.positions);
        gpu->refit();
        const std::vector<geom::Box3f> boxes = gpu->node_boxes();
        ASSERT_EQ(
            std::memcmp(boxes.data(), cpu_copy.boxes().data(), boxes.size() * sizeof(geom::Box3f)),
            0)
            << "n=" << n << " level_by_level=" << level_by_level << " frame " << frame;
      }
    }
  }
}

TEST(CudaDetect, HandBuiltCasesMatchTheCpuAndTheExpectedPairs) {
  SNAG_REQUIRE_GPU();
  for (const Case& c : cases()) {
    for (const auto& [m, offset] :
         {std::pair{&kIdentity, geom::Vec3d{0, 0, 0}}, std::pair{&kShear, geom::Vec3d{3, -5, 7}},
          std::pair{&kMirror, geom::Vec3d{-1000, 77, 5}}}) {
      const SmallMesh mesh = transformed(c.mesh, *m, offset);
      expect_same_filtered(mesh, c.name);
      const detect::FrameResult result = check_on_gpu(mesh);
      EXPECT_EQ(result.pairs, c.pairs) << c.name;
      EXPECT_EQ(result.degenerate, c.degenerate) << c.name;
    }
  }
}

TEST(CudaDetect, LatticeSoupsMatchTheCpuAndBruteForce) {
  SNAG_REQUIRE_GPU();
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const int32_t n = 20 + static_cast<int32_t>(seed * 7 % 90);
    const SmallMesh mesh = lattice_soup(n, n + static_cast<int32_t>(seed % 3) * n,
                                        3 + static_cast<int>(seed % 5), seed);
    expect_same_filtered(mesh, "seed " + std::to_string(seed));
    ASSERT_EQ(check_on_gpu(mesh).pairs, brute_force(mesh)) << "seed " << seed;
    ASSERT_EQ(check_on_gpu(mesh).pairs, check_mesh(mesh, 2).pairs) << "seed " << seed;
  }
}

TEST(CudaDetect, FoldedGridsMatchTheCpuAndBruteForce) {
  SNAG_REQUIRE_GPU();
  for (auto [w, h] : {std::pair{6, 4}, std::pair{11, 7}, std::pair{17, 9}, std::pair{40, 30}}) {
    const SmallMesh mesh = folded_grid(w, h);
    const std::vector<detect::FacePair> expected = brute_force(mesh);
    ASSERT_FALSE(expected.empty());
    expect_same_filtered(mesh, std::to_string(w) + "x" + std::to_string(h));
    EXPECT_EQ(check_on_gpu(mesh).pairs, expected) << w << "x" << h;
  }
}

/// `count` large triangles, each shifted by one along x and y from the last and raised by
/// `rise` along z: with rise 0 every pair overlaps (coplanar), with rise > 0 none does.
SmallMesh triangle_stack(int count, double rise) {
  SmallMesh stack;
  for (int i = 0; i < count; ++i) {
    const int32_t base = static_cast<int32_t>(stack.positions.size());
    const double z = rise * i;
    stack.positions.push_back({double(i), double(i), z});
    stack.positions.push_back({1000.0 + i, double(i), z});
    stack.positions.push_back({double(i), 1000.0 + i, z});
    stack.triangles.push_back({{base, base + 1, base + 2}});
  }
  return stack;
}

TEST(CudaDetect, ResultsComeBackSortedWhateverTheLastFrameLeftExpected) {
  SNAG_REQUIRE_GPU();
  // The ranking's grid is sized by the last frames' counts: after 60 frames of none it is one
  // slice by one, which then strides over the 28 slices of the next frame's 7,140 pairs, then
  // the grid grows again.
  const SmallMesh apart = triangle_stack(120, 1.0), together = triangle_stack(120, 0.0);
  detect::Checker checker(gpu_backend(), std::make_shared<IntegerResolver>());
  checker.set_triangles(apart.triangles, static_cast<int32_t>(apart.positions.size()));
  std::vector<const SmallMesh*> frames(60, &apart);
  frames.insert(frames.end(), {&together, &apart, &together, &together});
  const std::vector<detect::FacePair> all = brute_force(together);
  ASSERT_EQ(all.size(), 120u * 119u / 2u);
  for (size_t f = 0; f < frames.size(); ++f) {
    const detect::FrameResult result = checker.check(frames[f]->positions);
    if (frames[f] == &apart)
      EXPECT_TRUE(result.pairs.empty()) << "frame " << f;
    else
      EXPECT_EQ(result.pairs, all) << "frame " << f;
  }
}

TEST(CudaDetect, ResultsRankedOnEitherSideOfTheRankingsLimit) {
  SNAG_REQUIRE_GPU();
  // Stacks of n coplanar triangles have n(n-1)/2 pairs: 1 and 3 in part of one 256-key slice
  // of the ranking, 4,095 (16 slices, the last one short) and 4,186 (a 17th begun), 8,128 under
  // its limit (8,192) and 8,256 past it, where CUB's sort takes over, then 4,095 again. Each
  // size from a fresh backend and after the others.
  detect::Checker reused(gpu_backend(), std::make_shared<IntegerResolver>());
  for (int n : {2, 3, 91, 92, 128, 129, 91}) {
    const SmallMesh stack = triangle_stack(n, 0.0);
    const std::vector<detect::FacePair> expected = brute_force(stack);
    ASSERT_EQ(expected.size(), static_cast<size_t>(n) * (n - 1) / 2);
    EXPECT_EQ(check_on_gpu(stack).pairs, expected) << n << " triangles";
    reused.set_triangles(stack.triangles, static_cast<int32_t>(stack.positions.size()));
    EXPECT_EQ(reused.check(stack.positions).pairs, expected) << n << " triangles, reused";
  }
}

TEST(CudaDetect, MoreResultsThanTheBuffersHoldAreAllFound) {
  SNAG_REQUIRE_GPU();
  // A folded grid has hundreds of hits and uncertain tests; buffers of 1 and 7 entries must grow.
  const SmallMesh mesh = folded_grid(30, 20);
  for (int64_t capacity : {1, 7, 100})
    expect_same_filtered(mesh, "capacity " + std::to_string(capacity), capacity);
  // Overlapping coplanar copies: every pair intersects, 44,850 pairs from a 1-entry start.
  const SmallMesh stack = triangle_stack(300, 0.0);
  expect_same_filtered(stack, "coplanar stack", 1);
  auto gpu = gpu_backend();
  gpu->set_result_capacity(1);
  detect::Checker checker(std::move(gpu), std::make_shared<IntegerResolver>());
  checker.set_triangles(stack.triangles, static_cast<int32_t>(stack.positions.size()));
  const detect::FrameResult result = checker.check(stack.positions);
  EXPECT_EQ(result.pairs.size(), 300u * 299u / 2u);
  EXPECT_EQ(result.pairs, brute_force(stack));
}

TEST(CudaDetect, DuplicatedFacesAndNonManifoldEdgesFromTinyBuffersMatchTheCpu) {
  SNAG_REQUIRE_GPU();
  // The pair set's table has twice the slots of the pair buffer, sized from the last run; one
  // run can bring more distinct pairs than that: a hit on an edge of three faces makes three, a
  // duplicated face one more. A table that filled up left the expansion probing for a free
  // slot forever. This frame, from buffers of 1 and 7 entries (tables of 2 and 16 slots), runs
  // through the growth with duplicated faces and non-manifold edges; it did not fill the table
  // under the old probe on an H200 (the candidate list's capacity and the growth's slack keep
  // the keys of each run under it), so it checks the answers, not the hang (cuda/NOTES.md).
  SmallMesh mesh = folded_grid(30, 20);
  const size_t faces = mesh.triangles.size();
  for (size_t f = 0; f < faces; f += 10) mesh.triangles.push_back(mesh.triangles[f]);
  for (size_t f = 5; f < faces; f += 40) {  // fins: a third face on an edge, through the fold
    const geom::Tri face = mesh.triangles[f];
    const geom::Vec3d mid = 0.5 * (mesh.positions[face.v[0]] + mesh.positions[face.v[1]]);
    mesh.positions.push_back(mid + geom::Vec3d{0.5, 0.5, 3.0});
    mesh.triangles.push_back(
        {face.v[0], face.v[1], static_cast<int32_t>(mesh.positions.size() - 1)});
  }
  const detect::Topology topology =
      detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  auto cpu = detect::make_cpu_backend(2);
  cpu->set_topology(topology);
  const Filtered expected = filtered(*cpu, mesh.positions, true);
  ASSERT_GT(expected.frame.pairs.size(), 100u);  // hits and duplicated faces beyond the tables
  for (int64_t capacity : {1, 7})
    expect_same_filtered(mesh, "capacity " + std::to_string(capacity), capacity);
}

TEST(CudaDetect, RefitMatchesRebuildTheCpuAndBruteForceAfterDeformation) {
  SNAG_REQUIRE_GPU();
  SmallMesh mesh = folded_grid(15, 10);
  auto resolver = std::make_shared<IntegerResolver>();
  detect::Checker refitting(gpu_backend(), resolver, {detect::RebuildPolicy::never});
  detect::Checker rebuilding(gpu_backend(), resolver, {detect::RebuildPolicy::always});
  detect::Checker cpu(detect::make_cpu_backend(2), resolver, {detect::RebuildPolicy::never});
  for (detect::Checker* c : {&refitting, &rebuilding, &cpu})
    c->set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> step(-2, 2);
  for (int frame = 0; frame < 8; ++frame) {
    const detect::FrameResult a = refitting.check(mesh.positions);
    const detect::FrameResult b = rebuilding.check(mesh.positions);
    const detect::FrameResult c = cpu.check(mesh.positions);
    EXPECT_EQ(a.pairs, b.pairs) << "frame " << frame;
    EXPECT_EQ(a.pairs, c.pairs) << "frame " << frame;
    EXPECT_EQ(a.pairs, brute_force(mesh)) << "frame " << frame;
    EXPECT_EQ(a.degenerate, c.degenerate) << "frame " << frame;
    EXPECT_EQ(a.candidate_pairs, c.candidate_pairs) << "frame " << frame;
    EXPECT_EQ(a.filtered_tests, c.filtered_tests) << "frame " << frame;
    EXPECT_EQ(a.uncertain_tests, c.uncertain_tests) << "frame " << frame;
    EXPECT_EQ(a.tree_quality, c.tree_quality) << "frame " << frame;
    for (auto& p : mesh.positions)
      p = p + geom::Vec3d{double(step(rng)), double(step(rng)), double(step(rng))};
  }
}

TEST(CudaDetect, DegenerateFacesComeAndGoBetweenFrames) {
  SNAG_REQUIRE_GPU();
  // Frames that flatten some triangles to zero area and restore them: ownership moves to the
  // next incident face and back, and the device flags must follow.
  SmallMesh mesh = folded_grid(12, 8);
  const detect::Topology topology =
      detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  auto [cpu, gpu] = both_backends(topology);
  for (int frame = 0; frame < 4; ++frame) {
    SmallMesh moved = mesh;
    if (frame % 2 == 1) {
      // Collapse the first triangle of every other row: its third corner onto its first (zero
      // area the filter certifies: every projected difference is exactly zero).
      for (int t = 0; t < static_cast<int>(moved.triangles.size()); t += 48) {
        const geom::Tri tri = moved.triangles[t];
        moved.positions[tri.v[2]] = moved.positions[tri.v[0]];
      }
    }
    const Filtered c = filtered(*cpu, moved.positions, frame == 0);
    const Filtered g = filtered(*gpu, moved.positions, frame == 0);
    if (frame % 2 == 1) EXPECT_FALSE(c.scan.degenerate.empty());
    expect_same(c, g, "frame " + std::to_string(frame));
    EXPECT_EQ(check_on_gpu(moved).pairs, brute_force(moved)) << "frame " << frame;
  }
}

TEST(CudaDetect, PilesOfCollapsedTrianglesAndAZeroedFrameMatchTheCpu) {
  SNAG_REQUIRE_GPU();
  // Collapsed triangles' leaves have empty boxes on both backends (bvh::leaf_box): the same
  // degenerate lists, qualities, candidates and pairs as the CPU, and brute force's pairs.
  const SmallMesh piles = folded_grid_with_piles(500);
  expect_same_filtered(piles, "piles");
  EXPECT_EQ(check_on_gpu(piles).pairs, brute_force(piles));
  // A sequence with a frame whose positions were all zeroed, between two of the sheet.
  const SmallMesh mesh = folded_grid(12, 8);
  const detect::Topology topology =
      detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  auto [cpu, gpu] = both_backends(topology);
  SmallMesh zeroed = mesh;
  for (auto& p : zeroed.positions) p = {0.0, 0.0, 0.0};
  for (int frame = 0; frame < 3; ++frame) {
    const SmallMesh& at = frame == 1 ? zeroed : mesh;
    const Filtered c = filtered(*cpu, at.positions, frame == 0);
    const Filtered g = filtered(*gpu, at.positions, frame == 0);
    expect_same(c, g, "frame " + std::to_string(frame));
    if (frame == 1) {
      EXPECT_EQ(c.scan.degenerate.size(), mesh.triangles.size());
      EXPECT_EQ(g.frame.candidate_pairs, 0);
      EXPECT_EQ(g.quality, 0.0);
    }
  }
}

TEST(CudaDetect, RandomSoupsWithFilterDecisionsMatchTheCpu) {
  SNAG_REQUIRE_GPU();
  for (auto [n, size] : {std::pair{1000, 0.5}, std::pair{20000, 0.3}, std::pair{100000, 0.1}}) {
    const SmallMesh soup = random_soup(n, static_cast<uint32_t>(n), size);
    expect_same_filtered(soup, "soup " + std::to_string(n));
  }
}

TEST(CudaDetect, SharedDataFilesMatchTheCpu) {
  SNAG_REQUIRE_GPU();
  const std::filesystem::path data = data_dir();
  if (data.empty()) GTEST_SKIP() << "no shared data folder (../shared/data): data test skipped";
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(data)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".ply" && ext != ".obj")) continue;
    const mesh::Mesh m = io::read_mesh(entry.path());
    SmallMesh mesh{m.positions, m.triangles};
    expect_same_filtered(mesh, entry.path().string());
    ++files;
  }
  EXPECT_GT(files, 10);
}

TEST(CudaDetect, EveryTestDeferredMatchesTheCpu) {
  SNAG_REQUIRE_GPU();
  const auto defer = detect::FilterUse::defer_all;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const int32_t n = 20 + static_cast<int32_t>(seed * 7 % 90);
    const SmallMesh mesh = lattice_soup(n, n, 3 + static_cast<int>(seed % 5), seed);
    expect_same_filtered(mesh, "seed " + std::to_string(seed), 0, defer);
  }
  const SmallMesh grid = folded_grid(40, 30);
  expect_same_filtered(grid, "folded grid", 0, defer);
  // Far more tests than the buffers first hold: every one is deferred.
  expect_same_filtered(random_soup(20000, 7, 0.3), "soup 20000", 64, defer);
  // And nothing is decided on the way: no hit, no miss, only duplicates among the pairs.
  auto gpu = gpu_backend();
  const detect::Topology topology =
      detect::make_topology(grid.triangles, static_cast<int32_t>(grid.positions.size()));
  gpu->set_topology(topology);
  const Filtered f = filtered(*gpu, grid.positions, true, defer);
  EXPECT_TRUE(f.frame.pairs.empty());
  EXPECT_EQ(f.frame.filtered_tests, 0);
  EXPECT_GT(f.frame.uncertain.size(), static_cast<size_t>(f.frame.candidate_pairs));
}

TEST(CudaDetect, ExactModesMatchTheCpuAndBruteForce) {
  SNAG_REQUIRE_GPU();
  // Mode all needs a confirmer; brute force (exact integers, no tree) plays CGAL's part here.
  struct BruteForceConfirmer final : detect::PairConfirmer {
    std::vector<detect::FacePair> expected;
    std::vector<detect::Disagreement> confirm(const detect::ExactContext&,
                                              std::span<const detect::FacePair> pairs) override {
      std::vector<detect::Disagreement> wrong;
      for (const detect::FacePair& p : pairs)
        if (std::find(expected.begin(), expected.end(), p) == expected.end())
          wrong.push_back({p, "not a brute-force pair"});
      return wrong;
    }
  };
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const SmallMesh mesh = lattice_soup(80, 60, 4, seed);
    const std::vector<detect::FacePair> expected = brute_force(mesh);
    for (detect::ExactMode mode : {detect::ExactMode::off, detect::ExactMode::all}) {
      auto confirmer = std::make_shared<BruteForceConfirmer>();
      confirmer->expected = expected;
      detect::CheckSettings settings;
      settings.exact = mode;
      auto run = [&](std::unique_ptr<detect::Backend> backend) {
        detect::Checker checker(std::move(backend), std::make_shared<IntegerResolver>(), settings,
                                confirmer);
        checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
        return checker.check(mesh.positions);
      };
      const detect::FrameResult gpu = run(gpu_backend()), cpu = run(detect::make_cpu_backend(2));
      const std::string what =
          "seed " + std::to_string(seed) + " mode " + std::string(detect::to_string(mode));
      EXPECT_EQ(gpu.pairs, cpu.pairs) << what;
      EXPECT_EQ(gpu.degenerate, cpu.degenerate) << what;
      EXPECT_EQ(gpu.uncertain_tests, cpu.uncertain_tests) << what;
      if (mode == detect::ExactMode::all) {
        EXPECT_EQ(gpu.pairs, expected) << what;
        EXPECT_EQ(gpu.confirmed_pairs, static_cast<int64_t>(expected.size())) << what;
      }
    }
  }
}

// A sliver the rounded scan of `--exact off` flags degenerate although its fan is certified
// clear (tests/lib/fan_test.cpp): both backends leave its pairs out of the candidates.
TEST(CudaDetect, RoundedDegenerateSliverCountsAsOnTheCpu) {
  SNAG_REQUIRE_GPU();
  const double q = 1.0001905782366804, r = 1.0039064563594176, s = 1.0040977790816628;
  const SmallMesh mesh{{{0, 0, 0}, {1, q, q}, {r, s, s}, {0, 1, 1}, {1, 0, 0}},
                       {{{1, 2, 0}}, {{0, 4, 1}}, {{0, 2, 3}}}};
  detect::CheckSettings settings;
  settings.exact = detect::ExactMode::off;
  auto run = [&](std::unique_ptr<detect::Backend> backend) {
    detect::Checker checker(std::move(backend), nullptr, settings);
    checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
    return checker.check(mesh.positions);
  };
  const detect::FrameResult gpu = run(gpu_backend()), cpu = run(detect::make_cpu_backend(2));
  EXPECT_EQ(gpu.degenerate, std::vector<int32_t>{0});
  EXPECT_EQ(gpu.degenerate, cpu.degenerate);
  EXPECT_EQ(gpu.candidate_pairs, 1);
  EXPECT_EQ(gpu.candidate_pairs, cpu.candidate_pairs);
  EXPECT_EQ(gpu.filtered_tests, cpu.filtered_tests);
  EXPECT_EQ(gpu.pairs, cpu.pairs);
}

// A sheet rippled more every frame (refit, not rebuilt): at first every vertex's fan is clear
// and the subwalks leave nearly all neighbour pairs out of their lists (NeighborDrop); a frame
// with zero-area faces turns the leaving out off; at last the sheet folds through itself and
// fewer fans stay clear. Candidates, filtered tests and pairs are the CPU's in every frame, the
// pairs brute force's, and every neighbour pair is counted a candidate (their boxes touch).
TEST(CudaDetect, FanClearedNeighboursLeftOutCountAsOnTheCpu) {
  SNAG_REQUIRE_GPU();
  const int w = 50, h = 40;
  auto sheet = [&](double amplitude) {
    return grid_mesh(w, h, [&](int i, int j) {
      return geom::Vec3d{10.0 * i + j % 3, 10.0 * j,
                         std::round(amplitude * std::sin(i * 0.45) * std::cos(j * 0.3))};
    });
  };
  const SmallMesh flat = sheet(0);
  const detect::Topology topology =
      detect::make_topology(flat.triangles, static_cast<int32_t>(flat.positions.size()));
  ASSERT_FALSE(topology.fan_steps.empty());
  const int64_t neighbour_pairs = topology.neighbor_begin.back();
  auto [cpu, gpu] = both_backends(topology);
  SmallMesh degenerate = sheet(4);
  degenerate.positions[degenerate.triangles[500].v[0]] =
      degenerate.positions[degenerate.triangles[500].v[1]];
  const std::vector<std::pair<std::string, SmallMesh>> frames = {{"flat", flat},
                                                                 {"ripples 4", sheet(4)},
                                                                 {"zero-area faces", degenerate},
                                                                 {"ripples 12", sheet(12)},
                                                                 {"ripples 40", sheet(40)},
                                                                 {"folded", folded_grid(w, h)}};
  for (size_t f = 0; f < frames.size(); ++f) {
    const auto& [what, mesh] = frames[f];
    const Filtered c = filtered(*cpu, mesh.positions, f == 0);
    const Filtered g = filtered(*gpu, mesh.positions, f == 0);
    expect_same(c, g, what);
    if (what != "zero-area faces") EXPECT_EQ(g.frame.pairs.empty(), what != "folded") << what;
    if (g.scan.degenerate.empty())
      EXPECT_GE(g.frame.candidate_pairs, neighbour_pairs) << what;
    else
      EXPECT_EQ(what, "zero-area faces");
    if (f + 2 >= frames.size()) EXPECT_EQ(check_on_gpu(mesh).pairs, brute_force(mesh)) << what;
  }
}

TEST(CudaBackend, EmptyAndSingleTriangleMeshes) {
  SNAG_REQUIRE_GPU();
  SmallMesh empty;
  empty.positions = {{0, 0, 0}};
  EXPECT_TRUE(check_on_gpu(empty).pairs.empty());
  SmallMesh one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{{0, 1, 2}}}};
  EXPECT_TRUE(check_on_gpu(one).pairs.empty());
  expect_same_filtered(one, "one triangle");
}

TEST(CudaBackend, StreamTraceRecordsEachKernelOfAFrameOnce) {
  SNAG_REQUIRE_GPU();
  const SmallMesh a = folded_grid(20, 10);
  SmallMesh b = a;
  for (auto& p : b.positions) p = p + geom::Vec3d{0, 0, std::fmod(p.x * 5, 2.0)};
  const detect::Topology topology =
      detect::make_topology(a.triangles, static_cast<int32_t>(a.positions.size()));
  // Two backends one after the other: the records outlive the first, and the second's kernels
  // record as its did.
  for (int backend = 0; backend < 2; ++backend) {
    auto gpu = gpu_backend();
    gpu->set_topology(topology);  // kept by reference
    filtered(*gpu, a.positions, true);
    gpu->take_stream_trace();  // the build and what came before
    for (const SmallMesh* frame : {&std::as_const(b), &a}) {
      filtered(*gpu, frame->positions, false);  // scan, refit, quality, detect
      const std::vector<cuda::CudaBackend::TracedLaunch> launches = gpu->take_stream_trace();
      if (!cuda::stream_trace_compiled()) {
        EXPECT_TRUE(launches.empty()) << "a build without SNAG_CUDA_TRACE records nothing";
        continue;
      }
      // The frame's ten kernels, each once (the scan, the refit, the quality, the clearing, the
      // walks, the subwalks, the screen, the pair tests, the expansion, the ranking): only this
      // frame's, the records of the one before taken.
      EXPECT_EQ(launches.size(), 10u) << backend;
      for (size_t k = 0; k < launches.size(); ++k) {
        EXPECT_GT(launches[k].threads, 0) << k;
        // A block passes the wait after it began; the first block before the last; and a frame
        // takes well under a second (records left unreset would be far off).
        EXPECT_LE(launches[k].began, launches[k].passed_first) << k;
        EXPECT_LE(launches[k].passed_first, launches[k].passed_last) << k;
        EXPECT_LT(launches[k].passed_last, 1e6) << k;
      }
    }
  }
}

TEST(CudaBackend, ResidentFramesGiveTheSameResultsAsUploadedOnes) {
  SNAG_REQUIRE_GPU();
  SmallMesh a = folded_grid(20, 10), b = a;
  for (auto& p : b.positions) p = p + geom::Vec3d{0, 0, std::fmod(p.x * 7, 3.0)};
  const detect::Topology topology =
      detect::make_topology(a.triangles, static_cast<int32_t>(a.positions.size()));
  auto uploaded = gpu_backend(), resident = gpu_backend();
  uploaded->set_topology(topology);
  resident->set_topology(topology);
  const std::vector<std::span<const geom::Vec3d>> frames = {a.positions, b.positions};
  resident->upload_resident_frames(frames);
  for (int f : {0, 1, 0}) {
    resident->select_resident_frame(f);
    resident->build();
    const detect::FilteredFrame r = resident->detect({});
    const Filtered u = filtered(*uploaded, f == 0 ? a.positions : b.positions, true);
    EXPECT_EQ(r.pairs, u.frame.pairs) << f;
    EXPECT_EQ(r.uncertain, u.frame.uncertain) << f;
  }
}

/// `count` frames of `base`, each vertex stepping by -2 to 2 per axis per frame.
std::vector<SmallMesh> stepped_frames(SmallMesh base, int count, uint32_t seed) {
  std::vector<SmallMesh> frames;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> step(-2, 2);
  for (int f = 0; f < count; ++f) {
    frames.push_back(base);
    for (auto& p : base.positions)
      p = p + geom::Vec3d{double(step(rng)), double(step(rng)), double(step(rng))};
  }
  return frames;
}

TEST(CudaBackend, StagedNextFramesGiveTheResultsOfPlainUploads) {
  SNAG_REQUIRE_GPU();
  // A sequence checked with each next frame staged while the current one is checked, against
  // the CPU and brute force: staged frames used, a staged frame replaced by another, staging
  // skipped, a topology change after staging, and a big frame (copies long enough to overlap
  // the kernels) all give the plain answers.
  const SmallMesh base = folded_grid(60, 20);
  std::vector<SmallMesh> frames = stepped_frames(base, 12, 5);
  auto resolver = std::make_shared<IntegerResolver>();
  detect::Checker gpu(gpu_backend(), resolver);
  detect::Checker cpu(detect::make_cpu_backend(2), resolver);
  const int32_t vertices = static_cast<int32_t>(base.positions.size());
  for (detect::Checker* c : {&gpu, &cpu}) c->set_triangles(base.triangles, vertices);
  SmallMesh unrelated = frames[3];
  for (auto& p : unrelated.positions) p = p + geom::Vec3d{1, 0, 0};
  std::vector<geom::Tri> reversed = base.triangles;
  std::reverse(reversed.begin(), reversed.end());
  for (int f = 0; f < 12; ++f) {
    std::span<const geom::Vec3d> next;
    if (f + 1 < 12 && f != 4) next = frames[f + 1].positions;  // frame 5 arrives unstaged
    if (f == 7) next = unrelated.positions;  // staged, then not the frame that comes
    if (f == 9) {
      // A new face order after frame 9 was staged: the staged copy is dropped.
      const detect::FrameResult g = gpu.check(frames[f].positions, frames[f + 1].positions);
      EXPECT_EQ(g.pairs, cpu.check(frames[f].positions).pairs) << "frame " << f;
      for (detect::Checker* c : {&gpu, &cpu}) c->set_triangles(reversed, vertices);
      for (SmallMesh* m : {&frames[10], &frames[11]}) m->triangles = reversed;
      continue;
    }
    const detect::FrameResult g = gpu.check(frames[f].positions, next);
    const detect::FrameResult c = cpu.check(frames[f].positions);
    EXPECT_EQ(g.pairs, c.pairs) << "frame " << f;
    EXPECT_EQ(g.degenerate, c.degenerate) << "frame " << f;
    EXPECT_EQ(g.candidate_pairs, c.candidate_pairs) << "frame " << f;
    EXPECT_EQ(g.tree_quality, c.tree_quality) << "frame " << f;
    EXPECT_EQ(g.pairs, brute_force(frames[f])) << "frame " << f;
  }
}

TEST(CudaBackend, HostStagingHandsOutCopiesHeldUntilDropped) {
  SNAG_REQUIRE_GPU();
  // The pinned buffers a sequence's preparing thread stages positions in: each a copy at its
  // own address, held until its pointer is dropped, none when all are held (never a wait), a
  // buffer given back used again and grown for a larger frame; one staging per backend.
  auto gpu = gpu_backend();
  const std::shared_ptr<detect::HostStaging> staging = gpu->host_staging(2);
  ASSERT_NE(staging, nullptr);
  EXPECT_EQ(gpu->host_staging(5), staging);
  const std::vector<geom::Vec3d> small = folded_grid(6, 4).positions,
                                 large = folded_grid(40, 30).positions;
  auto as_vector = [](std::span<const geom::Vec3d> s) {
    return std::vector<geom::Vec3d>(s.begin(), s.end());
  };
  std::shared_ptr<const detect::StagedPositions> a = staging->stage(small);
  std::shared_ptr<const detect::StagedPositions> b = staging->stage(large);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(as_vector(a->positions()), small);
  EXPECT_EQ(as_vector(b->positions()), large);
  EXPECT_NE(a->positions().data(), small.data());
  EXPECT_NE(a->positions().data(), b->positions().data());
  EXPECT_EQ(staging->stage(small), nullptr);  // both buffers held
  a.reset();
  a = staging->stage(large);  // the small frame's buffer, grown
  ASSERT_NE(a, nullptr);
  const geom::Vec3d* was = a->positions().data();
  EXPECT_EQ(as_vector(a->positions()), large);
  EXPECT_EQ(as_vector(b->positions()), large);
  EXPECT_NE(a->positions().data(), b->positions().data());
  a.reset();
  a = staging->stage(small);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->positions().data(), was);  // given back again, used again
  EXPECT_EQ(as_vector(a->positions()), small);
  EXPECT_EQ(detect::make_cpu_backend(1)->host_staging(2), nullptr);  // nothing to stage
}

TEST(CudaBackend, StagedPositionsGiveThePlainAnswers) {
  SNAG_REQUIRE_GPU();
  // A sequence checked as snag check's loop does on a GPU: each frame staged in pinned memory
  // ahead of its check, its staged span checked and the next one's staged span passed ahead,
  // the frame's buffer given back once checked, against the CPU and brute force; buffers run
  // out (some frames then unstaged) and are used again by later frames. Then a frame staged in
  // a buffer given back while the transfer out of it is still queued: the staging waits for
  // that transfer before it writes, so the frame checked is the one staged.
  const SmallMesh base = folded_grid(40, 12);  // brute force on every frame: kept small
  const std::vector<SmallMesh> frames = stepped_frames(base, 10, 11);
  auto resolver = std::make_shared<IntegerResolver>();
  detect::Checker gpu(gpu_backend(), resolver);
  detect::Checker cpu(detect::make_cpu_backend(2), resolver);
  const int32_t vertices = static_cast<int32_t>(base.positions.size());
  for (detect::Checker* c : {&gpu, &cpu}) c->set_triangles(base.triangles, vertices);
  const std::shared_ptr<detect::HostStaging> staging = gpu.host_staging(2);
  ASSERT_NE(staging, nullptr);
  std::vector<std::shared_ptr<const detect::StagedPositions>> staged(frames.size());
  auto positions = [&](size_t f) {
    return staged[f] ? staged[f]->positions() : std::span<const geom::Vec3d>(frames[f].positions);
  };
  staged[0] = staging->stage(frames[0].positions);
  int unstaged = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    // Frames 4 and 5 hold a buffer for longer: 6 then finds none free.
    if (f + 1 < frames.size() && !staged[f + 1])
      staged[f + 1] = staging->stage(frames[f + 1].positions);
    unstaged += staged[f] == nullptr;
    const std::span<const geom::Vec3d> next =
        f + 1 < frames.size() ? positions(f + 1) : std::span<const geom::Vec3d>();
    const detect::FrameResult g = gpu.check(positions(f), next);
    const detect::FrameResult c = cpu.check(frames[f].positions);
    EXPECT_EQ(g.pairs, c.pairs) << "frame " << f;
    EXPECT_EQ(g.degenerate, c.degenerate) << "frame " << f;
    EXPECT_EQ(g.tree_quality, c.tree_quality) << "frame " << f;
    EXPECT_EQ(g.pairs, brute_force(frames[f])) << "frame " << f;
    if (f != 4) staged[f].reset();
    if (f == 6) staged[4].reset();
  }
  EXPECT_GT(unstaged, 0);
  EXPECT_LT(unstaged, 5);

  // One buffer: a frame's transfer queued from it (set_positions returns at once), the frame
  // given back and another staged over it at once, then the first frame checked. A big frame
  // (a height field of 1M triangles: no pairs), whose builds queued ahead of the transfer keep
  // the device busy long after the host has queued them. (At 120K the device kept pace with
  // the host's queueing, and a staging without its wait for the transfer passed half the runs
  // on an H200; at 1M it failed every round of five runs.) The other frame is stretched
  // unevenly, so that its tree's quality differs (and so would any mixture of the two).
  const SmallMesh big = grid_mesh(1000, 500, [](int i, int j) {
    return geom::Vec3d{double(i), double(j), double((i * j) % 5)};
  });
  SmallMesh moved = big;
  for (geom::Vec3d& p : moved.positions) p = geom::Vec3d{3 * p.x, p.y, 2 * p.z + 1};
  const detect::Topology topology =
      detect::make_topology(big.triangles, static_cast<int32_t>(big.positions.size()));
  auto plain = detect::make_cpu_backend(2);
  plain->set_topology(topology);
  const Filtered expected = filtered(*plain, big.positions, true);
  for (int round = 0; round < 3; ++round) {
    auto alone = gpu_backend();
    alone->set_topology(topology);
    const std::shared_ptr<detect::HostStaging> one = alone->host_staging(1);
    // Builds queued first (nothing in build() waits for them) hold the transfer back on the
    // stream, so that the second copy below is done before the transfer starts: without the
    // staging's wait for it, the transfer reads the second frame.
    alone->set_positions(moved.positions);
    for (int b = 0; b < 16; ++b) alone->build();
    std::shared_ptr<const detect::StagedPositions> first = one->stage(big.positions);
    ASSERT_NE(first, nullptr);
    alone->set_positions(first->positions());
    const geom::Vec3d* buffer = first->positions().data();
    first.reset();
    const std::shared_ptr<const detect::StagedPositions> second = one->stage(moved.positions);
    ASSERT_NE(second, nullptr);
    EXPECT_EQ(second->positions().data(), buffer);  // the same buffer, written over
    Filtered got;
    got.scan = alone->scan_degenerate();
    alone->build();
    got.quality = alone->tree_quality();
    got.frame = alone->detect(got.scan.degenerate);
    expect_same(expected, got, "round " + std::to_string(round));
  }
}

TEST(CudaBackend, AForgottenNextFrameIsNotTakenForItsSpanLater) {
  SNAG_REQUIRE_GPU();
  // A run cut short after staging its next frame (copied across during the check) leaves it
  // staged; its span may then hold another frame when a later run starts there. What snag
  // check's loop does first, forget_next_frame(), drops it: the span's new contents are the
  // frame checked. Without it the old copy would be taken (the two frames' pairs differ).
  const SmallMesh folded = folded_grid(40, 12);
  const SmallMesh flat = grid_mesh(40, 12, [](int i, int j) {
    return geom::Vec3d{double(i), double(2 * j), 0.0};
  });
  ASSERT_EQ(folded.positions.size(), flat.positions.size());
  ASSERT_FALSE(brute_force(folded).empty());
  ASSERT_TRUE(brute_force(flat).empty());
  detect::Checker gpu(gpu_backend(), std::make_shared<IntegerResolver>());
  gpu.set_triangles(folded.triangles, static_cast<int32_t>(folded.positions.size()));
  std::vector<geom::Vec3d> next = folded.positions;  // the span staged, then written over
  const std::vector<geom::Vec3d> first = folded.positions;
  EXPECT_EQ(gpu.check(first, next).pairs, brute_force(folded));
  // The run stops here; the span gets another frame (same size: the same storage); a new run
  // starts with it.
  const geom::Vec3d* was = next.data();
  next = flat.positions;
  ASSERT_EQ(next.data(), was);
  gpu.forget_next_frame();
  EXPECT_EQ(gpu.check(next).pairs, brute_force(flat));
}

/// Frames of a folded grid scaled by 4, each vertex stepping by -1, 0 or 1 per axis per frame,
/// a step undone where it would leave a triangle of zero area (so that consecutive frames have
/// the same, empty, degenerate list and a detect queued ahead can be taken).
inline std::vector<SmallMesh> wandering_frames(int w, int h, int count, uint32_t seed) {
  SmallMesh mesh = folded_grid(w, h);
  for (auto& p : mesh.positions) p = geom::Vec3d{4 * p.x, 4 * p.y, 4 * p.z};
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> step(-1, 1);
  // Zero area as brute_force decides it: exact integer predicates.
  auto flat = [&](const geom::Tri& t) {
    const IntegerPredicates pred{mesh.positions.data()};
    return IntegerResolver::decide(geom::is_degenerate(pred, t.v[0], t.v[1], t.v[2]));
  };
  std::vector<SmallMesh> frames;
  for (int f = 0; f < count; ++f) {
    frames.push_back(mesh);
    const std::vector<geom::Vec3d> before = mesh.positions;
    for (auto& p : mesh.positions)
      p = p + geom::Vec3d{double(step(rng)), double(step(rng)), double(step(rng))};
    for (bool undone = true; undone;) {
      undone = false;
      for (const geom::Tri& t : mesh.triangles)
        if (flat(t))
          for (int32_t v : t.v)
            if (mesh.positions[v] != before[v]) mesh.positions[v] = before[v], undone = true;
    }
  }
  return frames;
}

TEST(CudaBackend, FramesQueuedAheadGiveThePlainAnswers) {
  SNAG_REQUIRE_GPU();
  // A detect that finds the next frame staged queues that frame's refit, scan, quality and
  // detect before it returns. Each way the next calls can differ from what was queued gives
  // the CPU's answers: the queued work taken whole (frames whose pairs differ, none degenerate,
  // ~1,100-1,500 pairs: results through the mapped host sets); degenerate triangles appearing
  // and going (the queued detect assumed the last frame's); a rebuild; the current frame's
  // detect and quality asked again after the next one was queued (its trees refit back); a
  // frame set that is not the staged one; and, with capacity 1, every frame's buffers
  // overflowing and its results through the device-wide sorts. Compared filtered frame for
  // filtered frame (the checker's tests, StagedNextFrames and the scenes, take the same path
  // and compare the resolved pairs with brute force); ahead_taken() says the queued work was
  // taken exactly where it should be.
  const std::vector<SmallMesh> walk = wandering_frames(40, 14, 14, 17);
  std::vector<SmallMesh> frames = walk;
  for (int f : {4, 5, 9}) {
    // Zero area the filter certifies: a triangle's third corner onto its first.
    for (int t = f; t < static_cast<int>(frames[f].triangles.size()); t += 37) {
      const geom::Tri tri = frames[f].triangles[t];
      frames[f].positions[tri.v[2]] = frames[f].positions[tri.v[0]];
    }
  }
  // Another frame's positions at another address, with zero-area triangles where frame 12 has
  // none: a scan queued ahead for frame 12 would not find them.
  const SmallMesh unrelated = frames[4];
  const detect::Topology topology =
      detect::make_topology(walk[0].triangles, static_cast<int32_t>(walk[0].positions.size()));
  for (int64_t capacity : {int64_t{0}, int64_t{1}}) {
    auto [cpu, gpu] = both_backends(topology, capacity);
    for (int f = 0; f < 14; ++f) {
      const std::string what =
          "capacity " + std::to_string(capacity) + " frame " + std::to_string(f);
      const bool build = f == 0 || f == 7;  // frame 7: a rebuild after its work was queued ahead
      // Frame 11 is checked with frame 12 staged, then an unrelated frame of the same size comes.
      const std::span<const geom::Vec3d> positions =
          f == 12 ? std::span<const geom::Vec3d>(unrelated.positions) : frames[f].positions;
      Filtered g;
      gpu->set_positions(positions);
      if (f + 1 < 14) gpu->stage_positions(frames[f + 1].positions);
      g.scan = gpu->scan_degenerate();
      if (build)
        gpu->build();
      else
        gpu->refit();
      g.quality = gpu->tree_quality();
      g.frame = gpu->detect(g.scan.degenerate);
      const Filtered c = filtered(*cpu, positions, build);
      expect_same(c, g, what);
      if (f == 3 || f == 8) {
        // The current frame asked again, its next frame's work queued.
        expect_same_frame(c.frame, gpu->detect(g.scan.degenerate), what + ", asked again");
        EXPECT_EQ(gpu->tree_quality(), c.quality) << what << ", asked again";
      }
    }
    // Scans take the queued work in every frame but the first, the ones after a frame asked
    // again (4 and 9: refit back since) and the unrelated frame (12); detects where the scan did
    // and the degenerate triangles are the last frame's (not 5, 6, 10, nor 13 after the
    // unrelated frame's) and no tree was built since (not 7).
    const cuda::CudaBackend::AheadTaken taken = gpu->ahead_taken();
    EXPECT_EQ(taken.scans, 10) << "capacity " << capacity;
    EXPECT_EQ(taken.detects, 5) << "capacity " << capacity;  // frames 1, 2, 3, 8, 11
  }
}

/// A scene checked frame after frame on both backends; `capacity` > 0 starts the GPU's result
/// buffers (its subwalk and candidate lists included) that small, so that checks overflow them
/// and run again.
void expect_scene_matches(int64_t capacity) {
  // A folded cloth, a lattice body and a second sheet, checked as a scene frame after frame:
  // the cloth moves every frame, the body never, the sheet in some; frames 6 and 7 are frozen.
  // Next frames are staged with what moves in them. Every frame's pairs, degenerate faces,
  // candidates and per-check outcomes are the CPU's, and the pairs brute force's.
  const SmallMesh cloth = folded_grid(40, 12), body = lattice_soup(300, 200, 9, 3),
                  sheet = folded_grid(20, 9);
  Laid laid = lay_end_to_end({cloth, body, sheet});
  const std::vector<detect::PartCheck> checks = {{0, 0}, {0, 1}, {0, 2}, {2, 2}};
  std::vector<std::vector<geom::Vec3d>> frames;
  std::vector<std::vector<uint8_t>> moved;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> step(-1, 1);
  std::vector<geom::Vec3d> positions = laid.mesh.positions;
  for (int f = 0; f < 10; ++f) {
    std::vector<uint8_t> m = {1, 0, static_cast<uint8_t>(f % 3 == 0)};
    if (f == 6 || f == 7) m = {0, 0, 0};
    if (f > 0)
      for (int32_t part : {0, 2})
        if (m[part])
          for (int32_t v = laid.layout.vertex_begin[part]; v < laid.layout.vertex_begin[part + 1];
               ++v)
            positions[v] = positions[v] + geom::Vec3d{double(step(rng)), double(step(rng)), 0.0};
    frames.push_back(positions);
    moved.push_back(m);
  }
  auto resolver = std::make_shared<IntegerResolver>();
  std::unique_ptr<cuda::CudaBackend> backend = gpu_backend();
  if (capacity > 0) backend->set_result_capacity(capacity);
  detect::Checker gpu(std::move(backend), resolver), cpu(detect::make_cpu_backend(2), resolver);
  const auto vertices = static_cast<int32_t>(laid.mesh.positions.size());
  for (detect::Checker* c : {&gpu, &cpu})
    c->set_scene(laid.mesh.triangles, vertices, laid.layout, checks);
  for (int f = 0; f < 10; ++f) {
    detect::FrameInput input{frames[f], moved[f], {}, {}};
    if (f + 1 < 10 && f != 4) {
      input.next_positions = frames[f + 1];
      input.next_moved = moved[f + 1];
    }
    const detect::FrameResult g = gpu.check(input);
    const detect::FrameResult c = cpu.check({frames[f], moved[f], {}, {}});
    SmallMesh frame_mesh{frames[f], laid.mesh.triangles};
    EXPECT_EQ(g.pairs, c.pairs) << "capacity " << capacity << " frame " << f;
    EXPECT_EQ(g.pairs, expected_pairs({frame_mesh, laid.layout}, checks))
        << "capacity " << capacity << " frame " << f;
    EXPECT_EQ(g.degenerate, c.degenerate) << "capacity " << capacity << " frame " << f;
    EXPECT_EQ(g.candidate_pairs, c.candidate_pairs) << "capacity " << capacity << " frame " << f;
    ASSERT_EQ(g.checks.size(), c.checks.size());
    for (size_t k = 0; k < g.checks.size(); ++k) {
      EXPECT_EQ(g.checks[k].pairs, c.checks[k].pairs)
          << "capacity " << capacity << " frame " << f << " check " << k;
      EXPECT_EQ(g.checks[k].reused, c.checks[k].reused)
          << "capacity " << capacity << " frame " << f << " check " << k;
    }
    for (size_t p = 0; p < g.parts.size(); ++p)
      EXPECT_EQ(g.parts[p].tree_quality, c.parts[p].tree_quality)
          << "capacity " << capacity << " frame " << f;
  }
  EXPECT_EQ(gpu.build_count(), 3);
}

TEST(CudaScene, ScenesMatchTheCpuAndBruteForceAsPartsMoveAndRest) {
  SNAG_REQUIRE_GPU();
  expect_scene_matches(0);
}

TEST(CudaScene, ScenesMatchWhenEveryBufferOverflows) {
  SNAG_REQUIRE_GPU();
  expect_scene_matches(1);
}

// A part without triangles (an obstacle file without faces) has an empty tree on the GPU too.
TEST(CudaScene, APartWithoutTrianglesMatchesTheCpu) {
  SNAG_REQUIRE_GPU();
  auto resolver = std::make_shared<IntegerResolver>();
  for (const Laid& scene : scenes_with_an_empty_part()) {
    const std::vector<detect::PartCheck> checks = every_check(scene);
    detect::Checker gpu(gpu_backend(), resolver), cpu(detect::make_cpu_backend(2), resolver);
    for (detect::Checker* c : {&gpu, &cpu})
      c->set_scene(scene.mesh.triangles, static_cast<int32_t>(scene.mesh.positions.size()),
                   scene.layout, checks);
    Laid frame = scene;
    for (int f = 0; f < 3; ++f) {
      for (geom::Vec3d& p : frame.mesh.positions) p = p + geom::Vec3d{0.0, 0.0, double(f % 2)};
      const detect::FrameResult g = gpu.check(frame.mesh.positions);
      const detect::FrameResult c = cpu.check(frame.mesh.positions);
      EXPECT_EQ(g.pairs, c.pairs) << scene.layout.part_count() << " parts, frame " << f;
      EXPECT_EQ(g.pairs, expected_pairs(frame, checks))
          << scene.layout.part_count() << " parts, frame " << f;
      ASSERT_EQ(g.checks.size(), c.checks.size());
      for (size_t k = 0; k < g.checks.size(); ++k)
        EXPECT_EQ(g.checks[k].pairs, c.checks[k].pairs) << "frame " << f << " check " << k;
    }
  }
}

TEST(CudaBackend, BadDeviceIsAnError) {
  SNAG_REQUIRE_GPU();
  EXPECT_THROW(cuda::make_cuda_backend(cuda::cuda_device_count()), snag::InternalError);
  EXPECT_THROW(cuda::make_cuda_backend(-1), snag::InternalError);
}

TEST(CudaBackend, ADeviceThatRunsTheBuildHasNoProblemAndAMissingOneIsNamed) {
  SNAG_REQUIRE_GPU();
  // The GPUs the tests run on are among the build's architectures (the device machine's H200
  // and sm_90 by default): usable, so `--backend auto` takes them, and nothing to explain.
  const int count = cuda::cuda_device_count();
  for (int device = 0; device < count; ++device)
    EXPECT_EQ(cuda::cuda_device_problem(device), "") << "device " << device;
  EXPECT_EQ(cuda::cuda_runtime_problem(), "");
  const std::string missing = cuda::cuda_device_problem(count);
  EXPECT_NE(missing.find("no CUDA device " + std::to_string(count)), std::string::npos) << missing;
  EXPECT_NE(cuda::cuda_device_problem(-1), "");
  // The probe leaves no error pending for the next CUDA call to report as its own.
  EXPECT_NO_THROW(cuda::make_cuda_backend(0));
}

}  // namespace
}  // namespace snag::test
