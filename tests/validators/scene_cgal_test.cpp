// Scenes (a cloth and an obstacle laid end to end as two parts) against CGAL: snag's pairs
// between the parts are cgal_pairs_between's pair for pair, and their kinds CGAL's
// (cgal_pair_kind), on cloths draped through a UV sphere and over a box (crossing, touching
// exactly, missing by one ulp) and on ipc-toolkit's two cubes; a cloth checked against itself
// and the body at once gives CGAL's self pairs and cross pairs together.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <tuple>

#include "scene_cases.h"
#include "snag/detect/checker.h"
#include "snag/detect/cpu_backend.h"
#include "snag/io/read_mesh.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"
#include "test_paths.h"

namespace snag::validators {
namespace {

using Pairs = std::vector<std::pair<int32_t, int32_t>>;
using detect::FacePair;
using detect::PairKind;
using geom::Vec3d;
using test::grid_mesh;
using test::Laid;
using test::SmallMesh;

// ---- Generators ------------------------------------------------------------------------------

/// A UV sphere: the poles (vertices 0 and 1) and stacks - 1 rings of `slices` vertices.
SmallMesh uv_sphere(Vec3d center, double radius, int slices, int stacks) {
  SmallMesh mesh;
  mesh.positions.push_back({center.x, center.y, center.z + radius});
  mesh.positions.push_back({center.x, center.y, center.z - radius});
  for (int k = 1; k < stacks; ++k) {
    const double theta = std::numbers::pi * k / stacks;
    for (int s = 0; s < slices; ++s) {
      const double phi = 2 * std::numbers::pi * s / slices;
      mesh.positions.push_back(center + radius * Vec3d{std::sin(theta) * std::cos(phi),
                                                       std::sin(theta) * std::sin(phi),
                                                       std::cos(theta)});
    }
  }
  auto ring = [&](int k, int s) { return 2 + (k - 1) * slices + s % slices; };
  for (int s = 0; s < slices; ++s) {
    mesh.triangles.push_back({{0, ring(1, s), ring(1, s + 1)}});
    mesh.triangles.push_back({{1, ring(stacks - 1, s + 1), ring(stacks - 1, s)}});
    for (int k = 1; k + 1 < stacks; ++k) {
      mesh.triangles.push_back({{ring(k, s), ring(k + 1, s), ring(k + 1, s + 1)}});
      mesh.triangles.push_back({{ring(k, s), ring(k + 1, s + 1), ring(k, s + 1)}});
    }
  }
  return mesh;
}

/// An axis-aligned box [lo, hi], each face an n x n grid: every face lies exactly in its plane
/// (its constant coordinate is lo's or hi's value itself). Corners shared between faces are
/// one vertex.
SmallMesh box(Vec3d lo, Vec3d hi, int n) {
  SmallMesh mesh;
  std::map<std::tuple<double, double, double>, int32_t> ids;
  auto value = [&](int axis, int k) {
    const double a = geom::coord(lo, axis), b = geom::coord(hi, axis);
    return k == n ? b : a + (b - a) * k / n;
  };
  auto vertex = [&](int axis, double side, int k, int l) {
    double c[3];
    c[axis] = side;
    c[(axis + 1) % 3] = value((axis + 1) % 3, k);
    c[(axis + 2) % 3] = value((axis + 2) % 3, l);
    const auto [it, added] =
        ids.emplace(std::tuple{c[0], c[1], c[2]}, static_cast<int32_t>(mesh.positions.size()));
    if (added) mesh.positions.push_back({c[0], c[1], c[2]});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {geom::coord(lo, axis), geom::coord(hi, axis)})
      for (int k = 0; k < n; ++k)
        for (int l = 0; l < n; ++l) {
          const int32_t a = vertex(axis, side, k, l), b = vertex(axis, side, k + 1, l);
          const int32_t c = vertex(axis, side, k + 1, l + 1), d = vertex(axis, side, k, l + 1);
          mesh.triangles.push_back({{a, b, c}});
          mesh.triangles.push_back({{a, c, d}});
        }
  return mesh;
}

/// n + 1 values from `from` to `to`, the nearest to each of `exact` replaced by it: a grid
/// line then lies exactly on a box face's boundary.
std::vector<double> grid_values(double from, double to, int n, std::vector<double> exact) {
  std::vector<double> values;
  for (int k = 0; k <= n; ++k) values.push_back(from + (to - from) * k / n);
  for (double e : exact) {
    size_t nearest = 0;
    for (size_t k = 1; k < values.size(); ++k)
      if (std::abs(values[k] - e) < std::abs(values[nearest] - e)) nearest = k;
    values[nearest] = e;
  }
  return values;
}

/// A folded cloth (folded_grid's zig-zag with non-integer spacing): its rows pass through the
/// sheet, so it intersects itself.
SmallMesh folded_cloth(int w, int h, Vec3d origin) {
  return grid_mesh(w, h, [&](int i, int j) {
    const int fold = (i * 3) % (2 * w);
    return origin + Vec3d{0.1234 * (fold < w ? fold : 2 * w - fold), 0.2101 * j,
                          0.0731 * ((i * i) % 7) + 0.013 * std::sin(j)};
  });
}

/// A wavy cloth of n x n cells over [-half, half]^2 around `center`, domed upward by `dome`.
SmallMesh wavy_cloth(int n, double half, Vec3d center, double dome, double wave) {
  return grid_mesh(n, n, [&](int i, int j) {
    const double x = -half + 2 * half * i / n, y = -half + 2 * half * j / n;
    return center + Vec3d{x, y,
                          dome * std::exp(-(x * x + y * y)) +
                              wave * std::sin(1.7 * x + 0.3) * std::cos(2.3 * y)};
  });
}

// ---- Checking --------------------------------------------------------------------------------

detect::FrameResult snag_scene(const Laid& laid, const std::vector<detect::PartCheck>& checks,
                               int threads) {
  detect::Checker checker(detect::make_cpu_backend(threads), make_cgal_resolver());
  checker.set_scene(laid.mesh.triangles, static_cast<int32_t>(laid.mesh.positions.size()),
                    laid.layout, checks);
  return checker.check(laid.mesh.positions);
}

/// snag's pairs between parts a <= b of a scene, in each part's own triangle ids.
Pairs local_pairs(const detect::PartLayout& layout, std::span<const FacePair> pairs, int32_t a,
                  int32_t b) {
  Pairs local;
  for (const FacePair& p : pairs)
    if (test::part_of(layout, p.a) == a && test::part_of(layout, p.b) == b)
      local.emplace_back(p.a - layout.triangle_begin[a], p.b - layout.triangle_begin[b]);
  return local;
}

/// What a scene's check found, as CGAL gives it.
struct Found {
  Pairs pairs;
  int64_t crossing = 0;
};

/// `first` and `second` as parts 0 and 1 of a scene, only the check {0, 1} asked: snag's pairs
/// must be cgal_pairs_between's, every pair's kind CGAL's, and no face degenerate.
void expect_cross_agreement(const SmallMesh& first, const SmallMesh& second,
                            const std::string& what, Found* found) {
  const Laid laid = test::lay_end_to_end({first, second});
  const Pairs expected =
      cgal_pairs_between(first.positions, first.triangles, second.positions, second.triangles);
  for (int threads : {1, 3}) {
    const detect::FrameResult result = snag_scene(laid, {{0, 1}}, threads);
    ASSERT_TRUE(result.degenerate.empty()) << what;
    const Pairs cross = local_pairs(laid.layout, result.pairs, 0, 1);
    ASSERT_EQ(cross.size(), result.pairs.size()) << what << ": pairs outside the check asked";
    ASSERT_EQ(cross, expected) << what << ", threads " << threads;
    int64_t crossing = 0;
    for (const FacePair& p : result.pairs) {
      const PairKind kind =
          cgal_pair_kind(laid.mesh.positions, laid.mesh.triangles[p.a], laid.mesh.triangles[p.b]);
      ASSERT_EQ(p.kind, kind) << what << ": pair " << p.a << "," << p.b << " (scene ids)";
      crossing += kind == PairKind::crossing;
    }
    *found = {expected, crossing};
  }
}

// ---- The reference itself --------------------------------------------------------------------

TEST(SceneCgal, ReferenceHandCase) {
  // A: one triangle in the plane z = 0.1. B: a corner exactly on A's face, a far triangle, a
  // zero-area triangle through A (left out, reported apart by snag) and one piercing A.
  const SmallMesh a{{{0.1, 0.1, 0.1}, {1.3, 0.1, 0.1}, {0.1, 1.7, 0.1}}, {{{0, 1, 2}}}};
  const SmallMesh b{{{0.4, 0.5, 0.1},
                     {0.2, 0.3, 0.9},
                     {0.9, 0.2, 0.8},
                     {5.1, 5.1, 5.1},
                     {6.1, 5.1, 5.1},
                     {5.1, 6.1, 5.1},
                     {0.3, 0.3, -0.5},
                     {0.3, 0.3, 0.5},
                     {0.3, 0.3, 0.9},
                     {0.5, 0.4, -0.3},
                     {0.6, 0.5, 0.6},
                     {0.3, 0.7, 0.5}},
                    {{{0, 1, 2}}, {{3, 4, 5}}, {{6, 7, 8}}, {{9, 10, 11}}}};
  EXPECT_EQ(cgal_pairs_between(a.positions, a.triangles, b.positions, b.triangles),
            (Pairs{{0, 0}, {0, 3}}));
  EXPECT_EQ(cgal_pairs_between(b.positions, b.triangles, a.positions, a.triangles),
            (Pairs{{0, 0}, {3, 0}}));

  const Laid laid = test::lay_end_to_end({a, b});
  const detect::FrameResult result = snag_scene(laid, {{0, 1}}, 1);
  EXPECT_EQ(result.pairs,
            (std::vector<FacePair>{{0, 1, PairKind::touching}, {0, 4, PairKind::crossing}}));
  EXPECT_EQ(result.degenerate, (std::vector<int32_t>{3}));
}

TEST(SceneCgal, ReferenceIsEveryPairTestedOnGeneratedScenes) {
  // Closed boxes and the bipartite callback order: the box intersection must miss nothing
  // that testing every pair finds (faces of two meshes share no vertex: plain do_intersect).
  const SmallMesh sphere = uv_sphere({0.31, -0.17, 0.53}, 0.83, 20, 12);
  const Vec3d lo{-0.35, 0.15, -0.6}, hi{0.85, 1.05, 0.45};
  const SmallMesh body = box(lo, hi, 3);
  const auto xs = grid_values(-0.9, 1.4, 16, {lo.x, hi.x});
  const auto ys = grid_values(-0.3, 1.5, 12, {lo.y, hi.y});
  const SmallMesh pleated = grid_mesh(16, 12, [&](int i, int j) {
    return Vec3d{xs[i], ys[j], j % 2 ? hi.z + 0.05 + 0.02 * std::sin(i) : hi.z};
  });
  const std::vector<std::pair<SmallMesh, SmallMesh>> scenes = {
      {wavy_cloth(16, 1.4, {0.31, -0.17, 0.9}, 0.2, 0.07), sphere},
      {sphere, folded_cloth(12, 8, {-0.4, -0.9, 0.3})},
      {pleated, body}};
  int with_pairs = 0;
  for (size_t s = 0; s < scenes.size(); ++s) {
    const auto& [first, second] = scenes[s];
    const Laid laid = test::lay_end_to_end({first, second});
    Pairs every;
    for (int32_t i = 0; i < static_cast<int32_t>(first.triangles.size()); ++i)
      for (int32_t j = 0; j < static_cast<int32_t>(second.triangles.size()); ++j)
        if (cgal_faces_intersect(laid.mesh.positions, laid.mesh.triangles[i],
                                 laid.mesh.triangles[laid.layout.triangle_begin[1] + j]))
          every.emplace_back(i, j);
    EXPECT_EQ(
        cgal_pairs_between(first.positions, first.triangles, second.positions, second.triangles),
        every)
        << "scene " << s;
    with_pairs += !every.empty();
  }
  EXPECT_EQ(with_pairs, 3);
}

// ---- Cloth and sphere ------------------------------------------------------------------------

TEST(SceneCgal, WavyClothThroughSphereAtManyOffsets) {
  const Vec3d c{0.31, -0.17, 0.53};
  const SmallMesh sphere = uv_sphere(c, 0.83, 24, 14);
  int crossing_scenes = 0, missing_scenes = 0, scenes = 0;
  for (double lateral : {0.0, 0.55, 1.9, 3.7})
    for (double height : {-1.1, -0.7, -0.31, 0.0, 0.43, 0.79, 1.05}) {
      const std::string what =
          "lateral " + std::to_string(lateral) + " height " + std::to_string(height);
      const SmallMesh cloth =
          wavy_cloth(20, 1.5, c + Vec3d{lateral, 0.37 * lateral, height}, 0.15, 0.07);
      Found found;
      ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(cloth, sphere, what, &found));
      crossing_scenes += found.crossing > 0;
      missing_scenes += found.pairs.empty();
      ++scenes;
    }
  EXPECT_GE(crossing_scenes, 8);
  EXPECT_GE(missing_scenes, 7);  // lateral 3.7 misses whatever the height
  EXPECT_LT(missing_scenes, scenes);
}

TEST(SceneCgal, FoldedClothThroughSphere) {
  const SmallMesh sphere = uv_sphere({0.31, -0.17, 0.53}, 0.83, 24, 14);
  for (double z : {-0.4, 0.1, 0.6, 1.5}) {
    Found found;
    ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(folded_cloth(14, 9, {-0.5, -1.0, z}), sphere,
                                                   "folded cloth at z " + std::to_string(z),
                                                   &found));
    if (z < 1.0)
      EXPECT_GT(found.crossing, 0) << z;
    else
      EXPECT_TRUE(found.pairs.empty()) << z;
  }
}

/// Every pair joins a cloth triangle using cloth vertex `cv` and a body triangle using body
/// vertex `bv`, and there are exactly `count`.
void expect_contact_at(const Found& found, const SmallMesh& cloth, int32_t cv,
                       const SmallMesh& body, int32_t bv, size_t count, const std::string& what) {
  auto uses = [](const geom::Tri& t, int32_t v) {
    return t.v[0] == v || t.v[1] == v || t.v[2] == v;
  };
  EXPECT_EQ(found.pairs.size(), count) << what;
  EXPECT_EQ(found.crossing, 0) << what;
  for (const auto& [i, j] : found.pairs) {
    if (cv >= 0) EXPECT_TRUE(uses(cloth.triangles[i], cv)) << what << ": " << i << "," << j;
    EXPECT_TRUE(uses(body.triangles[j], bv)) << what << ": " << i << "," << j;
  }
}

TEST(SceneCgal, ClothTouchingSphereExactlyIsTouching) {
  const Vec3d c{0.31, -0.17, 0.53};
  const int slices = 24;
  const SmallMesh sphere = uv_sphere(c, 0.83, slices, 14);
  const Vec3d pole = sphere.positions[0];
  // A flat cloth in the pole's tangent plane z = pole.z, its column i = 4 at x = c.x exactly:
  // the pole on a cloth vertex, on a cloth edge (between rows), inside a cloth face.
  auto flat = [&](double dx, double dy, double z) {
    return grid_mesh(8, 8, [&](int i, int j) {
      return Vec3d{c.x + (i - 4) * 0.113 + dx, c.y + (j - 4) * 0.097 + dy, z};
    });
  };
  const int32_t center = 4 * 9 + 4;
  Found found;
  ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(flat(0, 0, pole.z), sphere, "on vertex", &found));
  expect_contact_at(found, flat(0, 0, pole.z), center, sphere, 0, 6 * slices, "on vertex");
  ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(flat(0, 0.04, pole.z), sphere, "on edge", &found));
  expect_contact_at(found, flat(0, 0.04, pole.z), -1, sphere, 0, 2 * slices, "on edge");
  ASSERT_NO_FATAL_FAILURE(
      expect_cross_agreement(flat(0.03, 0.05, pole.z), sphere, "in face", &found));
  expect_contact_at(found, flat(0.03, 0.05, pole.z), -1, sphere, 0, slices, "in face");

  // One ulp above the pole: nothing; one ulp below: the cloth cuts the pole's cap.
  const double above = std::nextafter(pole.z, 2 * pole.z);
  const double below = std::nextafter(pole.z, 0.0);
  ASSERT_NO_FATAL_FAILURE(
      expect_cross_agreement(flat(0.03, 0.05, above), sphere, "one ulp above", &found));
  EXPECT_TRUE(found.pairs.empty());
  ASSERT_NO_FATAL_FAILURE(
      expect_cross_agreement(flat(0.03, 0.05, below), sphere, "one ulp below", &found));
  EXPECT_EQ(found.pairs.size(), static_cast<size_t>(slices));
  EXPECT_EQ(found.crossing, slices);

  // A cloth cupped away from the sphere (a paraboloid in the sphere's tangent plane at a ring
  // vertex), its vertex (5, 5) exactly on that sphere vertex.
  const int32_t v = 2 + 3 * slices + 7;
  const Vec3d p = sphere.positions[v];
  const Vec3d d = p - c;
  const Vec3d n = (1 / std::sqrt(geom::dot(d, d))) * d;
  Vec3d e1 = geom::cross(n, {0, 0, 1});
  e1 = (1 / std::sqrt(geom::dot(e1, e1))) * e1;
  const Vec3d e2 = geom::cross(n, e1);
  const SmallMesh cup = grid_mesh(10, 10, [&](int i, int j) {
    const double u = (i - 5) * 0.09, w = (j - 5) * 0.11;
    return p + u * e1 + w * e2 + (0.8 * (u * u + w * w)) * n;
  });
  ASSERT_EQ(cup.positions[5 * 11 + 5], p);
  size_t around = 0;
  for (const geom::Tri& t : sphere.triangles) around += t.v[0] == v || t.v[1] == v || t.v[2] == v;
  ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(cup, sphere, "cup on ring vertex", &found));
  expect_contact_at(found, cup, 5 * 11 + 5, sphere, v, 6 * around, "cup on ring vertex");
}

// ---- Cloth and box ---------------------------------------------------------------------------

TEST(SceneCgal, ClothOverBox) {
  const Vec3d lo{-0.35, 0.15, -0.6}, hi{0.85, 1.05, 0.45};
  const SmallMesh body = box(lo, hi, 3);
  const auto xs = grid_values(-0.9, 1.4, 16, {lo.x, hi.x});
  const auto ys = grid_values(-0.3, 1.5, 12, {lo.y, hi.y});
  const double ulp_up = std::nextafter(hi.z, 1.0);
  // Pleats: even rows lie exactly on the top face's plane (their vertices on the face, on its
  // edges x = lo.x, hi.x and its corners; their edges along it), odd rows are raised.
  auto pleated = [&](double base) {
    return grid_mesh(16, 12, [&](int i, int j) {
      return Vec3d{xs[i], ys[j], j % 2 ? base + 0.05 + 0.02 * std::sin(i) : base};
    });
  };
  auto draped = [&](double base, double sag) {
    return grid_mesh(16, 12, [&](int i, int j) {
      const double x = xs[i] - 0.25, y = ys[j] - 0.6;
      return Vec3d{xs[i], ys[j], base - sag * std::exp(-4 * (x * x + y * y))};
    });
  };
  // Hanging against the side face x = lo.x: even columns in its plane, odd ones away from it.
  const auto side_ys = grid_values(-0.2, 1.4, 10, {lo.y, hi.y});
  const auto side_zs = grid_values(-0.9, 0.7, 10, {lo.z, hi.z});
  const SmallMesh hanging = grid_mesh(10, 10, [&](int i, int j) {
    return Vec3d{i % 2 ? lo.x - 0.04 - 0.01 * std::cos(j) : lo.x, side_ys[i], side_zs[j]};
  });
  // Vertical, through the box.
  const SmallMesh through = grid_mesh(10, 10, [&](int i, int j) {
    return Vec3d{0.21 + 0.05 * std::sin(1.3 * i + j), -0.3 + 0.17 * i, -0.9 + 0.16 * j};
  });
  const SmallMesh flat = grid_mesh(16, 12, [&](int i, int j) { return Vec3d{xs[i], ys[j], hi.z}; });

  struct Scene {
    const char* name;
    SmallMesh cloth;
    bool touches;  // exact contact only: pairs, none crossing
    bool crosses;
  };
  const std::vector<Scene> scenes = {
      {"pleated on top", pleated(hi.z), true, false},
      {"pleated one ulp above", pleated(ulp_up), false, false},
      {"flat on top", flat, true, false},
      {"draped over the top", draped(hi.z + 0.2, 0.15), false, false},
      {"draped into the top", draped(hi.z + 0.2, 0.45), false, true},
      {"hanging on the side", hanging, true, false},
      {"through", through, false, true},
      {"above", pleated(hi.z + 0.3), false, false}};
  for (const Scene& scene : scenes) {
    Found found;
    ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(scene.cloth, body, scene.name, &found));
    if (scene.touches) {
      EXPECT_FALSE(found.pairs.empty()) << scene.name;
      EXPECT_EQ(found.crossing, 0) << scene.name;
    } else if (scene.crosses) {
      EXPECT_GT(found.crossing, 0) << scene.name;
    } else {
      EXPECT_TRUE(found.pairs.empty()) << scene.name;
    }
  }
}

// ---- Self and cross together -----------------------------------------------------------------

TEST(SceneCgal, SelfAndCrossPairsTogether) {
  const SmallMesh cloth = folded_cloth(14, 9, {-0.5, -1.0, 0.1});
  const SmallMesh sphere = uv_sphere({0.31, -0.17, 0.53}, 0.83, 24, 14);
  const Pairs self = cgal_soup_self_intersections(cloth.positions, cloth.triangles);
  ASSERT_FALSE(self.empty());
  // The cloth first and then second: its self pairs in scene ids are offset by the sphere's
  // triangles in the second case.
  for (const int32_t cloth_part : {0, 1}) {
    const Laid laid = cloth_part == 0 ? test::lay_end_to_end({cloth, sphere})
                                      : test::lay_end_to_end({sphere, cloth});
    const SmallMesh& first = cloth_part == 0 ? cloth : sphere;
    const SmallMesh& second = cloth_part == 0 ? sphere : cloth;
    const Pairs cross =
        cgal_pairs_between(first.positions, first.triangles, second.positions, second.triangles);
    ASSERT_FALSE(cross.empty());
    const detect::FrameResult result = snag_scene(laid, {{cloth_part, cloth_part}, {0, 1}}, 2);
    const Pairs snag_self = local_pairs(laid.layout, result.pairs, cloth_part, cloth_part);
    const Pairs snag_cross = local_pairs(laid.layout, result.pairs, 0, 1);
    EXPECT_EQ(snag_self, self) << "cloth as part " << cloth_part;
    EXPECT_EQ(snag_cross, cross) << "cloth as part " << cloth_part;
    EXPECT_EQ(snag_self.size() + snag_cross.size(), result.pairs.size());
    for (const FacePair& p : result.pairs)
      ASSERT_EQ(p.kind, cgal_pair_kind(laid.mesh.positions, laid.mesh.triangles[p.a],
                                       laid.mesh.triangles[p.b]))
          << p.a << "," << p.b;
  }
}

// ---- ipc-toolkit's two cubes -----------------------------------------------------------------

/// A two-cubes file as two parts: the connected components of its face-vertex graph, which
/// the file lays out one after the other (the first cube's faces and used vertices all before
/// the second's; a vertex no face uses stays with the cube before it).
struct Split {
  SmallMesh first, second;
  int32_t first_triangles = 0, first_vertices = 0;
};

Split split_in_two(const mesh::Mesh& mesh) {
  const auto n = static_cast<int32_t>(mesh.positions.size());
  std::vector<int32_t> parent(n);
  for (int32_t v = 0; v < n; ++v) parent[v] = v;
  auto root = [&](int32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const geom::Tri& t : mesh.triangles)
    for (int k = 1; k < 3; ++k) parent[root(t.v[k])] = root(t.v[0]);
  Split split;
  const int32_t first_root = root(mesh.triangles.front().v[0]);
  while (split.first_triangles < static_cast<int32_t>(mesh.triangles.size()) &&
         root(mesh.triangles[split.first_triangles].v[0]) == first_root)
    ++split.first_triangles;
  int32_t first_max = 0, second_min = n;
  for (int32_t t = 0; t < static_cast<int32_t>(mesh.triangles.size()); ++t)
    for (int32_t v : mesh.triangles[t].v) {
      if (t < split.first_triangles)
        first_max = std::max(first_max, v);
      else
        second_min = std::min(second_min, v);
      EXPECT_EQ(root(v) == first_root, t < split.first_triangles)
          << "triangle " << t << ": the file's components are not laid out one after the other";
    }
  EXPECT_LT(first_max, second_min) << "the cubes' vertices interleave";
  split.first_vertices = second_min;
  split.first.positions.assign(mesh.positions.begin(), mesh.positions.begin() + second_min);
  split.second.positions.assign(mesh.positions.begin() + second_min, mesh.positions.end());
  for (int32_t t = 0; t < static_cast<int32_t>(mesh.triangles.size()); ++t) {
    geom::Tri tri = mesh.triangles[t];
    if (t < split.first_triangles) {
      split.first.triangles.push_back(tri);
    } else {
      for (int32_t& v : tri.v) v -= second_min;
      split.second.triangles.push_back(tri);
    }
  }
  return split;
}

struct CubesFile {
  const char* path;
  size_t cross_pairs;
};

class SceneCgalCubes : public ::testing::TestWithParam<CubesFile> {};

TEST_P(SceneCgalCubes, CrossPairsAreCgals) {
  const auto data = test::data_dir();
  if (data.empty())
    GTEST_SKIP() << "../shared/data is absent (set SNAG_DATA_DIR): skipping the two-cubes scenes";
  const auto path = data / GetParam().path;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is missing";
  const mesh::Mesh mesh = io::read_mesh(path);
  ASSERT_EQ(mesh.triangles.size(), 480u);
  const Split split = split_in_two(mesh);
  ASSERT_EQ(split.first_triangles, 240);  // two cubes of 240 triangles each
  ASSERT_FALSE(::testing::Test::HasFailure());
  Found found;
  ASSERT_NO_FATAL_FAILURE(expect_cross_agreement(split.first, split.second, path.string(), &found));
  EXPECT_EQ(found.pairs.size(), GetParam().cross_pairs) << path;

  // The file's own vertex ids and layout (its unused vertices included) give the same pairs.
  detect::PartLayout layout;
  layout.triangle_begin = {0, split.first_triangles, static_cast<int32_t>(mesh.triangles.size())};
  layout.vertex_begin = {0, split.first_vertices, static_cast<int32_t>(mesh.positions.size())};
  const detect::FrameResult result =
      snag_scene({{mesh.positions, mesh.triangles}, layout}, {{0, 1}}, 2);
  EXPECT_EQ(local_pairs(layout, result.pairs, 0, 1), found.pairs);
}

INSTANTIATE_TEST_SUITE_P(SceneCgalTwoCubes, SceneCgalCubes,
                         ::testing::Values(CubesFile{"ipc-toolkit/two-cubes-far.ply", 0},
                                           CubesFile{"ipc-toolkit/two-cubes-close.ply", 0},
                                           CubesFile{"ipc-toolkit/two-cubes-intersecting.ply", 96}),
                         [](const ::testing::TestParamInfo<CubesFile>& info) {
                           std::string name = std::filesystem::path(info.param.path).stem();
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace snag::validators
