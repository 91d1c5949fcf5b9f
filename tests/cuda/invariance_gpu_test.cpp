// Issue 4's invariance property on the CUDA backend: on the random near-degenerate soups, the
// hand-built cases and the hard-case corpus, the answer under every exact transform of
// tests/invariance.h (pairs in original ids, kinds, degenerate faces) is the reference answer
// (CGAL's; for the corpus, its written answers, which CGAL confirms), with --exact uncertain and
// all. The same inputs and transforms as tests/validators/invariance_test.cpp, which checks the
// CPU backend.
// Without a GPU every test skips with a loud message (CI has nvcc but no GPU).
#include <gtest/gtest.h>

#include <cstdio>

#include "detect_cases.h"
#include "invariance.h"
#include "require_gpu.h"
#include "snag/cuda/cuda_backend.h"
#include "snag/validators/exact_modes.h"

namespace snag::test {
namespace {

/// The CUDA backend on device 0 with --exact uncertain and all, a fresh checker per mesh.
std::vector<Method> gpu_methods() {
  std::vector<Method> methods;
  for (detect::ExactMode mode : {detect::ExactMode::uncertain, detect::ExactMode::all})
    methods.push_back(
        {"cuda, --exact " + std::string(detect::to_string(mode)), [mode](const SmallMesh& mesh) {
           detect::CheckSettings settings;
           settings.exact = mode;
           auto checker = validators::make_checker(cuda::make_cuda_backend(0), settings);
           checker->set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
           return checker->check(mesh.positions);
         }});
  return methods;
}

TEST(InvarianceGpu, RandomNearDegenerateSoupsAreCgalsAnswerUnderEveryTransform) {
  SNAG_REQUIRE_GPU();
  const std::vector<Method> methods = gpu_methods();
  int compared = 0;
  for (uint32_t seed = 0; seed < 24; ++seed) {
    const NearDegenerateSettings settings = near_degenerate_settings(seed);
    const SmallMesh mesh = near_degenerate_soup(seed, settings);
    const std::string what = describe(seed, settings);
    std::vector<Transformed> transforms = standard_transforms(mesh, seed);
    ASSERT_GE(translation_count(transforms), 3) << what;
    transforms.insert(transforms.begin(), identity(mesh));
    compared += expect_invariant(transforms, methods, cgal_answer(mesh), what);
    if (HasFailure()) return;
  }
  std::printf("%d comparisons\n", compared);
}

TEST(InvarianceGpu, HandBuiltCasesKeepTheirExactAnswerUnderEveryTransform) {
  SNAG_REQUIRE_GPU();
  const std::vector<Method> methods = gpu_methods();
  uint32_t seed = 100;
  for (const Case& c : cases()) {
    const Answer expected{c.pairs, c.degenerate};
    ASSERT_EQ(cgal_answer(c.mesh), expected) << c.name;
    for (const SmallMesh& mesh : {c.mesh, transformed(c.mesh, kShear, {1 << 20, 3, -7})}) {
      std::vector<Transformed> transforms = standard_transforms(mesh, ++seed);
      transforms.insert(transforms.begin(), identity(mesh));
      expect_invariant(transforms, methods, expected, c.name);
      if (HasFailure()) return;
    }
  }
}

TEST(InvarianceGpu, HardCaseCorpusKeepsItsWrittenAnswerUnderEveryTransform) {
  SNAG_REQUIRE_GPU();
  const std::vector<HardCase> corpus = hard_cases();
  if (corpus.empty())
    GTEST_SKIP() << "no samples/hard under " << source_dir()
                 << ": the hard-case corpus is absent, its invariance is not checked";
  const std::vector<Method> methods = gpu_methods();
  uint32_t seed = 500;
  for (const HardCase& c : corpus) {
    ASSERT_EQ(cgal_answer(c.mesh), c.expected) << c.name;
    std::vector<Transformed> transforms = standard_transforms(c.mesh, ++seed);
    transforms.insert(transforms.begin(), identity(c.mesh));
    expect_invariant(transforms, methods, c.expected, c.name);
    if (HasFailure()) return;
  }
  std::printf("%zu cases\n", corpus.size());
}

}  // namespace
}  // namespace snag::test
