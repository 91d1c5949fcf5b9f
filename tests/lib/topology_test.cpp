// The topology's edges, ownership and neighbour pairs against brute-force definitions, on
// random meshes with shared vertices, repeated corners and fans above the listed valence.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "snag/detect/topology.h"
#include "snag/error.h"

namespace snag::detect {
namespace {

bool repeats_corner(const geom::Tri& t) {
  return t.v[0] == t.v[1] || t.v[1] == t.v[2] || t.v[2] == t.v[0];
}

/// `count` triangles over `vertices` vertices, a few with a repeated corner, and `hub_count`
/// more around vertex 0 so that its fan is larger than the listed valence.
std::vector<geom::Tri> random_mesh(int32_t vertices, int32_t count, int32_t hub_count,
                                   uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int32_t> vertex(0, vertices - 1);
  std::vector<geom::Tri> triangles;
  for (int32_t i = 0; i < count; ++i) {
    geom::Tri t{{vertex(rng), vertex(rng), vertex(rng)}};
    if (i % 17 != 3)  // mostly proper triangles; every 17th may repeat a corner
      while (repeats_corner(t)) t = geom::Tri{{vertex(rng), vertex(rng), vertex(rng)}};
    triangles.push_back(t);
  }
  for (int32_t i = 0; i < hub_count; ++i) {
    geom::Tri t{{0, vertex(rng), vertex(rng)}};
    while (repeats_corner(t)) t = geom::Tri{{0, vertex(rng), vertex(rng)}};
    triangles.insert(triangles.begin() + (i * 7) % static_cast<int32_t>(triangles.size()), t);
  }
  return triangles;
}

void expect_matches_brute_force(const std::vector<geom::Tri>& triangles, int32_t vertices) {
  const Topology topo = make_topology(triangles, vertices);
  const auto n = static_cast<int32_t>(triangles.size());

  // Edges: unique (u < v), in increasing order; each with its incident proper triangles.
  std::map<std::array<int32_t, 2>, std::vector<int32_t>> incident;
  std::vector<int32_t> index_degenerate;
  for (int32_t t = 0; t < n; ++t) {
    if (repeats_corner(triangles[t])) {
      index_degenerate.push_back(t);
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const int32_t a = triangles[t].v[k], b = triangles[t].v[(k + 1) % 3];
      incident[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  }
  EXPECT_EQ(topo.index_degenerate, index_degenerate);
  ASSERT_EQ(topo.edges.size(), incident.size());
  ASSERT_EQ(topo.edge_face_offsets.size(), incident.empty() ? 1 : incident.size() + 1);
  size_t e = 0;
  for (const auto& [edge, faces] : incident) {
    EXPECT_EQ(topo.edges[e], edge) << "edge " << e;
    const std::vector<int32_t> listed(topo.edge_faces.begin() + topo.edge_face_offsets[e],
                                      topo.edge_faces.begin() + topo.edge_face_offsets[e + 1]);
    EXPECT_EQ(listed, faces) << "faces of edge " << e;
    ++e;
  }
  // Each triangle's edge ids and ownership: the smallest incident triangle owns an edge.
  for (int32_t t = 0; t < n; ++t) {
    uint8_t owned = 0;
    for (int k = 0; k < 3; ++k) {
      if (repeats_corner(triangles[t])) {
        EXPECT_EQ(topo.triangle_edges[t][k], -1);
        continue;
      }
      const int32_t a = triangles[t].v[k], b = triangles[t].v[(k + 1) % 3];
      const std::array<int32_t, 2> edge{std::min(a, b), std::max(a, b)};
      const int32_t id = topo.triangle_edges[t][k];
      ASSERT_GE(id, 0);
      EXPECT_EQ(topo.edges[id], edge) << "triangle " << t << " edge " << k;
      if (incident[edge].front() == t) owned |= static_cast<uint8_t>(1u << k);
    }
    EXPECT_EQ(topo.owned_edges[t], owned) << "triangle " << t;
  }

  // Neighbour pairs: proper triangles sharing a vertex whose fan of proper triangles is at
  // most kMaxListedValence, with their shared-corner masks.
  std::vector<int32_t> valence(static_cast<size_t>(vertices), 0);
  for (int32_t t = 0; t < n; ++t)
    if (!repeats_corner(triangles[t]))
      for (int k = 0; k < 3; ++k) ++valence[triangles[t].v[k]];
  bool every_listed = true;
  for (int32_t v = 0; v < vertices; ++v) {
    const bool listed = valence[v] <= Topology::kMaxListedValence;
    every_listed = every_listed && listed;
    EXPECT_EQ(topo.listed_vertex[v], listed ? 1 : 0) << "vertex " << v;
  }
  EXPECT_EQ(topo.every_vertex_listed, every_listed);
  std::vector<std::array<int32_t, 2>> pairs;
  std::vector<uint8_t> shared;
  for (int32_t a = 0; a < n; ++a)
    for (int32_t b = a + 1; b < n; ++b) {
      if (repeats_corner(triangles[a]) || repeats_corner(triangles[b])) continue;
      bool listed = false;
      uint32_t a_shared = 0, b_shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (triangles[a].v[i] == triangles[b].v[j]) {
            listed = listed || valence[triangles[a].v[i]] <= Topology::kMaxListedValence;
            a_shared |= 1u << i;
            b_shared |= 1u << j;
          }
      if (!listed) continue;
      pairs.push_back({a, b});
      shared.push_back(static_cast<uint8_t>(a_shared | b_shared << 3));
    }
  EXPECT_EQ(topo.neighbor_pairs, pairs);
  EXPECT_EQ(topo.neighbor_shared, shared);
  std::vector<int64_t> begin(static_cast<size_t>(n) + 1, 0);
  for (const auto& [a, b] : pairs) ++begin[a + 1];
  for (int32_t t = 0; t < n; ++t) begin[t + 1] += begin[t];
  EXPECT_EQ(topo.neighbor_begin, begin);
}

TEST(Topology, EdgesOwnershipAndNeighbourPairsMatchBruteForce) {
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    const int32_t vertices = 8 + static_cast<int32_t>(seed) * 9;
    const std::vector<geom::Tri> triangles =
        random_mesh(vertices, 40 + 25 * static_cast<int32_t>(seed), seed % 3 == 0 ? 40 : 0, seed);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(triangles.size()) +
                 " triangles over " + std::to_string(vertices) + " vertices");
    expect_matches_brute_force(triangles, vertices);
    if (HasFailure()) return;
  }
}

TEST(Topology, OwnershipWithoutAFramesDegenerateTrianglesMatchesBruteForce) {
  // A frame's zero-area triangles own nothing: each edge goes to its smallest incident triangle
  // that is not degenerate this frame, however many degenerate ones come before it. Few
  // vertices, so that edges have many faces (and several degenerate ones each).
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const int32_t vertices = 6 + static_cast<int32_t>(seed % 5);
    const std::vector<geom::Tri> triangles = random_mesh(vertices, 60, 0, 100 + seed);
    const Topology topo = make_topology(triangles, vertices);
    const auto n = static_cast<int32_t>(triangles.size());
    std::mt19937 rng(seed);
    for (int share : {10, 40, 70, 100}) {  // percent of the proper triangles made degenerate
      std::vector<int32_t> degenerate;
      for (int32_t t = 0; t < n; ++t)
        if (!repeats_corner(triangles[t]) && static_cast<int>(rng() % 100) < share)
          degenerate.push_back(t);
      const std::vector<uint8_t> owned = ownership_without(topo, degenerate);
      ASSERT_EQ(owned.size(), static_cast<size_t>(n));
      const auto is_degenerate = [&](int32_t t) {
        return repeats_corner(triangles[t]) ||
               std::binary_search(degenerate.begin(), degenerate.end(), t);
      };
      for (int32_t t = 0; t < n; ++t) {
        uint8_t expected = 0;
        for (int k = 0; k < 3 && !is_degenerate(t); ++k) {
          const int32_t a = triangles[t].v[k], b = triangles[t].v[(k + 1) % 3];
          int32_t owner = -1;  // the smallest triangle on edge {a, b} that is not degenerate
          for (int32_t f = 0; f < n && owner < 0; ++f)
            for (int kk = 0; kk < 3; ++kk) {
              const int32_t c = triangles[f].v[kk], d = triangles[f].v[(kk + 1) % 3];
              if (!is_degenerate(f) && std::min(a, b) == std::min(c, d) &&
                  std::max(a, b) == std::max(c, d))
                owner = f;
            }
          if (owner == t) expected |= static_cast<uint8_t>(1u << k);
        }
        ASSERT_EQ(owned[t], expected)
            << "seed " << seed << ", " << share << "% degenerate, triangle " << t;
      }
    }
  }
}

// A vertex used by exactly kMaxListedValence triangles is listed, one used by one more is not:
// closed fans of 32 triangles around vertex 0 and of 33 around vertex 33.
TEST(Topology, AVertexOfExactlyTheListedValenceIsListed) {
  std::vector<geom::Tri> triangles;
  const auto add_fan = [&](int32_t hub, int32_t k) {  // hub, then its ring hub + 1 .. hub + k
    for (int32_t i = 0; i < k; ++i)
      triangles.push_back(geom::Tri{{hub, hub + 1 + i, hub + 1 + (i + 1) % k}});
  };
  const int32_t k = Topology::kMaxListedValence;
  add_fan(0, k);
  add_fan(k + 1, k + 1);
  const int32_t vertices = 2 * k + 3;
  const Topology topo = make_topology(triangles, vertices);
  EXPECT_EQ(topo.listed_vertex[0], 1);
  EXPECT_EQ(topo.listed_vertex[k + 1], 0);
  expect_matches_brute_force(triangles, vertices);
}

/// Two copies of one random mesh (20 vertices, 60 triangles) laid end to end as two parts.
struct TwoParts {
  std::vector<geom::Tri> one = random_mesh(20, 60, 0, 5);
  std::vector<geom::Tri> both;
  PartLayout layout;
  TwoParts() {
    both = one;
    for (geom::Tri t : one) {
      for (int32_t& v : t.v) v += 20;
      both.push_back(t);
    }
    layout.triangle_begin = {0, 60, 120};
    layout.vertex_begin = {0, 20, 40};
  }
};

// A part not checked against itself lists no neighbour pairs (its pairs are never tested); a
// part that is lists those of the mesh alone (brute force), moved to its triangles.
TEST(Topology, OnlyPartsCheckedAgainstThemselvesListNeighbourPairs) {
  const TwoParts m;
  expect_matches_brute_force(m.one, 20);
  const Topology alone = make_topology(m.one, 20);
  const Topology scene = make_scene_topology(m.both, 40, m.layout, {{0, 1}, {1, 1}});
  std::vector<std::array<int32_t, 2>> moved;
  for (const auto& [a, b] : alone.neighbor_pairs) moved.push_back({a + 60, b + 60});
  EXPECT_EQ(scene.neighbor_pairs, moved);
  EXPECT_EQ(scene.neighbor_shared, alone.neighbor_shared);
  ASSERT_EQ(scene.neighbor_begin.size(), 121u);
  for (int32_t t = 0; t <= 60; ++t) EXPECT_EQ(scene.neighbor_begin[t], 0) << "triangle " << t;
  for (int32_t t = 0; t <= 60; ++t)
    EXPECT_EQ(scene.neighbor_begin[60 + t], alone.neighbor_begin[t]) << "triangle " << 60 + t;
}

// A check may name its two parts in either order; one naming a part that does not exist is
// refused in either order; and the parts' vertices must be exactly the mesh's.
TEST(Topology, SceneChecksAndLayoutsAreValidated) {
  const TwoParts m;
  const Topology topo = make_scene_topology(m.both, 40, m.layout, {{1, 0}, {1, 1}, {0, 1}});
  EXPECT_EQ(topo.checks, (std::vector<PartCheck>{{0, 1}, {1, 1}}));
  EXPECT_THROW(make_scene_topology(m.both, 40, m.layout, {{2, 0}}), InternalError);
  EXPECT_THROW(make_scene_topology(m.both, 40, m.layout, {{1, -1}}), InternalError);
  // One vertex more than the parts hold (no triangle uses it).
  EXPECT_THROW(make_scene_topology(m.both, 41, m.layout, {{0, 0}}), InternalError);
}

TEST(Topology, EmptyAndAllDegenerateMeshes) {
  expect_matches_brute_force({}, 3);
  expect_matches_brute_force({geom::Tri{{0, 0, 1}}, geom::Tri{{2, 2, 2}}}, 3);
}

}  // namespace
}  // namespace snag::detect
