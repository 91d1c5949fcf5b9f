// Test meshes shared by the lib and cuda tests: the hand-built cases with their exact expected
// pairs and kinds, random and lattice soups, folded grids, integer affine maps, and the brute-force
// O(n^2) reference finder over exact integer predicates.
#pragma once

#include <random>
#include <vector>

#include "lib/detect_fixture.h"

namespace snag::test {

using detect::FacePair;
using detect::PairKind;
inline constexpr PairKind kCrossing = PairKind::crossing;
inline constexpr PairKind kTouching = PairKind::touching;

struct Case {
  const char* name;
  SmallMesh mesh;
  std::vector<FacePair> pairs;
  std::vector<int32_t> degenerate;
};

inline std::vector<Case> cases() {
  std::vector<Case> all;
  // A base triangle F in z = 0 with corners 0, 1, 2.
  const std::vector<geom::Vec3d> base = {{0, 0, 0}, {8, 0, 0}, {0, 8, 0}};
  auto with = [&](std::vector<geom::Vec3d> more) {
    std::vector<geom::Vec3d> p = base;
    p.insert(p.end(), more.begin(), more.end());
    return p;
  };
  all.push_back({"shared edge folded flat",
                 {with({{4, 4, 0}}), {{{0, 1, 2}}, {{0, 1, 3}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back(
      {"shared edge flat continuation", {with({{4, -4, 0}}), {{{0, 1, 2}}, {{1, 0, 3}}}}, {}, {}});
  all.push_back({"shared edge hinge", {with({{4, 4, 5}}), {{{0, 1, 2}}, {{0, 1, 3}}}}, {}, {}});
  all.push_back({"shared vertex, opposite edge piercing",
                 {with({{2, 2, -2}, {2, 2, 2}}), {{{0, 1, 2}}, {{0, 3, 4}}}},
                 {{0, 1, kCrossing}},
                 {}});
  all.push_back({"shared vertex only",
                 {with({{-2, -2, 3}, {-3, 1, 4}}), {{{0, 1, 2}}, {{0, 3, 4}}}},
                 {},
                 {}});
  all.push_back({"shared vertex, edge lying in the face",
                 {with({{2, 2, 0}, {1, 1, 5}}), {{{0, 1, 2}}, {{0, 3, 4}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"shared vertex, coplanar outside the angle",
                 {with({{-2, -2, 0}, {-4, 1, 0}}), {{{0, 1, 2}}, {{0, 3, 4}}}},
                 {},
                 {}});
  all.push_back({"coplanar overlap",
                 {with({{1, 1, 0}, {12, 1, 0}, {1, 12, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"coplanar, one inside the other",
                 {with({{1, 1, 0}, {3, 1, 0}, {1, 3, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"coplanar apart",
                 {with({{9, 9, 0}, {12, 9, 0}, {9, 12, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {},
                 {}});
  all.push_back({"vertex exactly on the face",
                 {with({{2, 2, 0}, {3, 2, 4}, {2, 3, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"vertex exactly on an edge",
                 {with({{4, 0, 0}, {5, -1, 4}, {4, 1, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"vertex a hair above the face",
                 {with({{2, 2, 1}, {3, 2, 4}, {2, 3, 4}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {},
                 {}});
  all.push_back({"edge exactly through an edge",
                 {with({{4, -2, 0}, {4, 2, 0}, {4, 0, 6}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  // X's edge 3-4 crosses F's edge 0-1 at (4, 0, 0), and X meets F's plane along a segment
  // that leaves F there: both straddle, contact at one point.
  all.push_back({"edge across an edge at a point",
                 {with({{4, -2, -2}, {4, 2, 2}, {6, -4, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"segment contact without passing through",
                 {with({{1, 1, 0}, {3, 1, 0}, {2, 1, 5}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"proper crossing",
                 {with({{1, 1, -3}, {3, 1, 3}, {2, 4, 3}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kCrossing}},
                 {}});
  // Both straddle, and the two segments on the planes' line meet only at an end: (4, 0, 0).
  all.push_back({"straddling, segments meet at one point",
                 {with({{4, -4, -4}, {4, -4, 4}, {4, 0, 0}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {{0, 1, kTouching}},
                 {}});
  all.push_back({"duplicated face", {base, {{{0, 1, 2}}, {{1, 2, 0}}}}, {{0, 1, kTouching}}, {}});
  all.push_back({"zero-area face through a triangle",
                 {with({{1, 1, -3}, {2, 2, 0}, {3, 3, 3}}), {{{0, 1, 2}}, {{3, 4, 5}}}},
                 {},
                 {1}});
  all.push_back({"repeated corner", {with({{1, 1, -3}}), {{{0, 1, 2}}, {{3, 3, 0}}}}, {}, {1}});
  return all;
}

inline constexpr int kIdentity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
inline constexpr int kShear[3][3] = {{1, 2, 0}, {0, 1, 3}, {1, 0, 1}};    // det 7
inline constexpr int kMirror[3][3] = {{0, 1, 0}, {1, 0, 0}, {-2, 3, 1}};  // det -1: a reflection

/// Every pair of non-degenerate triangles, decided straight from the definition (an edge of
/// either meets the other beyond their shared endpoints; a duplicated face always), with the
/// exact integer predicates: no tree, no representative triangles, no filter.
inline std::vector<detect::FacePair> brute_force(const SmallMesh& mesh) {
  const IntegerPredicates pred{mesh.positions.data()};
  const auto n = static_cast<int32_t>(mesh.triangles.size());
  std::vector<uint8_t> degenerate(static_cast<size_t>(n));
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri& tri = mesh.triangles[t];
    degenerate[t] =
        IntegerResolver::decide(geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]));
  }
  auto edge_hits = [&](const geom::Tri& f, const geom::Tri& x) {
    for (int k = 0; k < 3; ++k) {
      const int32_t p = f.v[k], q = f.v[(k + 1) % 3];
      const bool p_in = p == x.v[0] || p == x.v[1] || p == x.v[2],
                 q_in = q == x.v[0] || q == x.v[1] || q == x.v[2];
      if (p_in && q_in) continue;
      if (IntegerResolver::decide(geom::edge_hits_triangle(
              pred, p, q, x, IntegerResolver::side(pred, x, p), IntegerResolver::side(pred, x, q))))
        return true;
    }
    return false;
  };
  std::vector<detect::FacePair> pairs;
  for (int32_t a = 0; a < n; ++a) {
    if (degenerate[a]) continue;
    for (int32_t b = a + 1; b < n; ++b) {
      if (degenerate[b]) continue;
      const geom::Tri &fa = mesh.triangles[a], &fb = mesh.triangles[b];
      int shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) shared += fa.v[i] == fb.v[j];
      if (shared == 3 || edge_hits(fa, fb) || edge_hits(fb, fa)) {
        const bool crossing = IntegerResolver::decide(geom::is_crossing(pred, fa, fb));
        pairs.push_back({a, b, crossing ? detect::PairKind::crossing : detect::PairKind::touching});
      }
    }
  }
  return pairs;
}

/// A triangle soup on a coarse integer lattice: coincident vertices, coplanar and collinear
/// configurations, shared ids (a vertex pool smaller than 3n) and zero-area faces all occur.
inline SmallMesh lattice_soup(int32_t triangles, int32_t vertices, int range, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(0, range);
  std::uniform_int_distribution<int32_t> pick(0, vertices - 1);
  SmallMesh mesh;
  for (int32_t v = 0; v < vertices; ++v)
    mesh.positions.push_back({double(coord(rng)), double(coord(rng)), double(coord(rng))});
  for (int32_t t = 0; t < triangles; ++t)
    mesh.triangles.push_back({{pick(rng), pick(rng), pick(rng)}});
  return mesh;
}

/// n triangles with three vertices of their own each: centres uniform in a 10-unit cube, corners
/// within `size` of the centre in each coordinate (non-integer coordinates: the filter decides).
inline SmallMesh random_soup(int32_t n, uint32_t seed, double size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> where(0.0, 10.0), offset(-size, size);
  SmallMesh soup;
  for (int32_t t = 0; t < n; ++t) {
    const geom::Vec3d c{where(rng), where(rng), where(rng)};
    for (int k = 0; k < 3; ++k)
      soup.positions.push_back(c + geom::Vec3d{offset(rng), offset(rng), offset(rng)});
    soup.triangles.push_back({{3 * t, 3 * t + 1, 3 * t + 2}});
  }
  return soup;
}

/// Collapses every `every`-th triangle of a soup whose triangles have three vertices of their own
/// (random_soup), from `first` on: in turn all three corners onto `pile`, one point shared by all
/// of them, then the second corner onto the first, the third onto the second and the first onto
/// the third (each pair that bvh::leaf_box compares). Zero-area triangles whose leaves get the
/// empty box. Returns their ids in order.
inline std::vector<int32_t> collapse_soup_triangles(SmallMesh& soup, int32_t every, int32_t first,
                                                    geom::Vec3d pile) {
  std::vector<int32_t> collapsed;
  const auto n = static_cast<int32_t>(soup.triangles.size());
  for (int32_t t = first; t < n; t += every) {
    const geom::Tri tri = soup.triangles[t];
    const auto turn = static_cast<int>(collapsed.size() % 4);
    if (turn == 0)
      for (int k = 0; k < 3; ++k) soup.positions[tri.v[k]] = pile;
    else  // corner `turn % 3` onto corner `turn - 1`
      soup.positions[tri.v[turn % 3]] = soup.positions[tri.v[turn - 1]];
    collapsed.push_back(t);
  }
  return collapsed;
}

/// A grid of w x h cells, vertex (i, j) at `at(i, j)`, each cell split along the diagonal
/// from (i, j) to (i + 1, j + 1): an interior vertex has 6 triangles, an edge along i or j
/// has 2.
template <class At>
SmallMesh grid_mesh(int w, int h, At at) {
  SmallMesh mesh;
  for (int j = 0; j <= h; ++j)
    for (int i = 0; i <= w; ++i) mesh.positions.push_back(at(i, j));
  auto id = [&](int i, int j) { return j * (w + 1) + i; };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      mesh.triangles.push_back({{id(i, j), id(i + 1, j), id(i + 1, j + 1)}});
      mesh.triangles.push_back({{id(i, j), id(i + 1, j + 1), id(i, j + 1)}});
    }
  return mesh;
}

/// A folded grid: a w x h sheet whose rows bend back through the sheet, in integer coordinates.
inline SmallMesh folded_grid(int w, int h) {
  return grid_mesh(w, h, [w](int i, int j) {
    const int fold = (i * 3) % (2 * w);  // zig-zag in x: the sheet passes through itself
    return geom::Vec3d{double(fold < w ? fold : 2 * w - fold), double(j * 2), double((i * i) % 7)};
  });
}

/// folded_grid(12, 8) with `piled` triangles of three vertices of their own after its own, all
/// at one point: in turn its vertex 40 (a corner of six of its triangles) and a point inside one
/// of its faces. A zeroed or collapsed region in a frame of a real cache, whose triangles are
/// listed as degenerate and pair with nothing. Their ids are the last `piled`.
inline SmallMesh folded_grid_with_piles(int32_t piled) {
  SmallMesh mesh = folded_grid(12, 8);
  const geom::Tri face = mesh.triangles[17];
  const geom::Vec3d inside = mesh.positions[face.v[0]] + mesh.positions[face.v[1]] +
                             mesh.positions[face.v[2]];  // scaled by 3 with the sheet below
  for (auto& p : mesh.positions) p = 3.0 * p;
  const geom::Vec3d piles[2] = {mesh.positions[40], inside};
  for (int32_t i = 0; i < piled; ++i) {
    const auto first = static_cast<int32_t>(mesh.positions.size());
    for (int k = 0; k < 3; ++k) mesh.positions.push_back(piles[i % 2]);
    mesh.triangles.push_back({{first, first + 1, first + 2}});
  }
  return mesh;
}

}  // namespace snag::test
