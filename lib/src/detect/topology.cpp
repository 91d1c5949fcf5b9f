#include "snag/detect/topology.h"

#include <algorithm>

#include "snag/detect/pair_test.h"
#include "snag/error.h"

namespace snag::detect {

namespace {

struct EdgeRecord {
  int32_t u, v;  // endpoints, u < v
  int32_t triangle;
  int32_t corner;  // the triangle's edge k joins corners k and k + 1
};

/// Per part: 1 when it is checked against itself (its neighbour pairs are listed, its
/// vertices get fans).
std::vector<uint8_t> self_checked_parts(const Topology& topo) {
  std::vector<uint8_t> self(static_cast<size_t>(topo.part_count()), 0);
  for (const PartCheck& c : topo.checks)
    if (c.self()) self[c.a] = 1;
  return self;
}

/// The fan of vertex v (Topology::fan_steps) from its usable triangles `around` (increasing
/// ids, at most kMaxListedValence), appended to topo.fan_steps; nothing when they do not form
/// one strip around v or form one too short to hold a pair.
void append_fan(Topology& topo, int32_t v, std::span<const int32_t> around) {
  const auto k = static_cast<int32_t>(around.size());
  if (k < 2) return;
  // Each triangle's corners after v in its own order: (v, next, prev).
  std::array<int32_t, Topology::kMaxListedValence> next, prev;
  for (int32_t i = 0; i < k; ++i) {
    const geom::Tri t = topo.triangles[around[i]];
    const int c = t.v[0] == v ? 0 : (t.v[1] == v ? 1 : 2);
    next[i] = t.v[(c + 1) % 3];
    prev[i] = t.v[(c + 2) % 3];
  }
  // How many of the triangles each neighbouring vertex is in: a strip has every one in two,
  // or (open) exactly two ends in one.
  auto uses = [&](int32_t a) {
    int32_t count = 0;
    for (int32_t i = 0; i < k; ++i) count += (next[i] == a) + (prev[i] == a);
    return count;
  };
  int32_t first = 0, start = next[0], ends = 0;
  for (int32_t i = 0; i < k; ++i)
    for (const int32_t a : {next[i], prev[i]}) {
      const int32_t count = uses(a);
      if (count > 2) return;
      if (count == 1 && ends++ == 0) {  // the first end found lies in the smallest such triangle
        first = i;
        start = a;
      }
    }
  if (ends != 0 && ends != 2) return;
  const bool closed = ends == 0;
  if (closed && k < 3) return;  // two triangles on the same three vertices: a duplicated face
  const auto begin = topo.fan_steps.size();
  std::array<bool, Topology::kMaxListedValence> used{};
  int32_t at = first, corner = start;
  for (int32_t step = 0; step < k; ++step) {
    used[at] = true;
    const bool reversed = next[at] != corner;  // t runs (v, a_{i+1}, a_i)
    topo.fan_steps.push_back({corner, 2 * around[at] + (reversed ? 1 : 0)});
    corner = reversed ? next[at] : prev[at];  // a_{i+1}
    if (step + 1 == k) break;
    at = -1;
    for (int32_t i = 0; i < k && at < 0; ++i)
      if (!used[i] && (next[i] == corner || prev[i] == corner)) at = i;
    if (at < 0) break;  // the strip ended before taking every triangle: more than one strip
  }
  const bool whole =
      topo.fan_steps.size() - begin == static_cast<size_t>(k) && (!closed || corner == start);
  if (!whole) {
    topo.fan_steps.resize(begin);
    return;
  }
  if (!closed) topo.fan_steps.push_back({corner, -1});
}

/// Lists the pairs of triangles around each vertex of valence at most kMaxListedValence, in
/// (a, b) order without sorting the list: each triangle t gathers the later triangles of its
/// listed corners' fans (a few dozen at most), sorts and dedupes those, and the triangles
/// come in increasing id.
void make_neighbor_pairs(Topology& topo) {
  const int32_t n = topo.triangle_count();
  std::vector<uint8_t> usable(static_cast<size_t>(n), 1);
  for (int32_t t : topo.index_degenerate) usable[t] = 0;
  // Triangles around each vertex (CSR), in increasing id.
  std::vector<int32_t> offsets(static_cast<size_t>(topo.vertex_count) + 1, 0);
  for (int32_t t = 0; t < n; ++t)
    if (usable[t])
      for (int k = 0; k < 3; ++k) ++offsets[topo.triangles[t].v[k] + 1];
  for (int32_t v = 0; v < topo.vertex_count; ++v) offsets[v + 1] += offsets[v];
  std::vector<int32_t> fan(static_cast<size_t>(offsets.back()));
  std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
  for (int32_t t = 0; t < n; ++t)
    if (usable[t])
      for (int k = 0; k < 3; ++k) fan[fill[topo.triangles[t].v[k]]++] = t;
  topo.listed_vertex.assign(static_cast<size_t>(topo.vertex_count), 0);
  topo.every_vertex_listed = true;
  for (int32_t v = 0; v < topo.vertex_count; ++v) {
    if (offsets[v + 1] - offsets[v] > Topology::kMaxListedValence)
      topo.every_vertex_listed = false;
    else
      topo.listed_vertex[v] = 1;
  }
  // The fans of the listed vertices of parts checked against themselves.
  const std::vector<uint8_t> self_part = self_checked_parts(topo);
  topo.fan_begin.assign(static_cast<size_t>(topo.vertex_count) + 1, 0);
  topo.fan_steps.clear();
  // FanStep::face holds 2 t + 1: meshes of 2^30 triangles or more get no fans.
  const bool fans_fit = n < (int32_t{1} << 30);
  for (int32_t p = 0; p < topo.part_count(); ++p)
    for (int32_t v = topo.layout.vertex_begin[p]; v < topo.layout.vertex_begin[p + 1]; ++v) {
      if (fans_fit && self_part[p] && topo.listed_vertex[v])
        append_fan(topo, v,
                   std::span<const int32_t>(fan.data() + offsets[v], fan.data() + offsets[v + 1]));
      topo.fan_begin[v + 1] = static_cast<int32_t>(topo.fan_steps.size());
    }
  std::vector<std::array<int32_t, 2>>& pairs = topo.neighbor_pairs;
  pairs.clear();
  topo.neighbor_shared.clear();
  // About 7 a triangle in a cloth: reserved, so that the list is not copied as it grows.
  pairs.reserve(static_cast<size_t>(n) * 8);
  topo.neighbor_shared.reserve(static_cast<size_t>(n) * 8);
  std::array<int32_t, 3 * Topology::kMaxListedValence> later;
  for (int32_t t = 0; t < n; ++t) {
    if (!usable[t]) continue;
    const geom::Tri tri = topo.triangles[t];
    size_t count = 0;
    for (int k = 0; k < 3; ++k) {
      const int32_t v = tri.v[k];
      if (!topo.listed_vertex[v]) continue;
      const int32_t* begin = fan.data() + offsets[v];
      const int32_t* end = fan.data() + offsets[v + 1];
      for (const int32_t* x = std::upper_bound(begin, end, t); x != end; ++x) later[count++] = *x;
    }
    std::sort(later.begin(), later.begin() + count);
    const auto unique_end = std::unique(later.begin(), later.begin() + count);
    for (auto x = later.begin(); x != unique_end; ++x) {
      uint32_t t_shared, x_shared;
      shared_corners(tri, topo.triangles[*x], t_shared, x_shared);
      pairs.push_back({t, *x});
      topo.neighbor_shared.push_back(static_cast<uint8_t>(t_shared | x_shared << 3));
    }
  }
}

/// Keeps the neighbour pairs of the parts checked against themselves and records where each
/// triangle's pairs begin (the list is sorted by its first triangle). The kept pairs are moved
/// to the front in place (a pair is never written ahead of where it is read).
void select_self_neighbors(Topology& topo) {
  const int32_t parts = topo.part_count();
  const std::vector<uint8_t> self = self_checked_parts(topo);
  const int32_t n = topo.triangle_count();
  topo.neighbor_begin.assign(static_cast<size_t>(n) + 1, 0);
  size_t i = 0, kept = 0;
  const size_t count = topo.neighbor_pairs.size();
  for (int32_t p = 0; p < parts; ++p)
    for (int32_t t = topo.layout.triangle_begin[p]; t < topo.layout.triangle_begin[p + 1]; ++t) {
      for (; i < count && topo.neighbor_pairs[i][0] == t; ++i)
        if (self[p]) {
          topo.neighbor_pairs[kept] = topo.neighbor_pairs[i];
          topo.neighbor_shared[kept] = topo.neighbor_shared[i];
          ++kept;
        }
      topo.neighbor_begin[t + 1] = static_cast<int64_t>(kept);
    }
  topo.neighbor_pairs.resize(kept);
  topo.neighbor_shared.resize(kept);
}

}  // namespace

Topology make_topology(std::span<const geom::Tri> triangles, int32_t vertex_count) {
  PartLayout layout;
  layout.triangle_begin = {0, static_cast<int32_t>(triangles.size())};
  layout.vertex_begin = {0, vertex_count};
  return make_scene_topology(triangles, vertex_count, std::move(layout), {PartCheck{0, 0}});
}

int32_t PartLayout::part_of(int32_t t) const {
  return static_cast<int32_t>(
      std::upper_bound(triangle_begin.begin() + 1, triangle_begin.end() - 1, t) -
      (triangle_begin.begin() + 1));
}

int32_t Topology::part_of(int32_t t) const {
  return layout.part_of(t);
}

Topology make_scene_topology(std::span<const geom::Tri> triangles, int32_t vertex_count,
                             PartLayout layout, std::vector<PartCheck> checks) {
  const int32_t parts = layout.part_count();
  if (parts < 1 || layout.vertex_begin.size() != layout.triangle_begin.size() ||
      layout.triangle_begin.front() != 0 || layout.vertex_begin.front() != 0 ||
      layout.triangle_begin.back() != static_cast<int32_t>(triangles.size()) ||
      layout.vertex_begin.back() != vertex_count ||
      !std::is_sorted(layout.triangle_begin.begin(), layout.triangle_begin.end()) ||
      !std::is_sorted(layout.vertex_begin.begin(), layout.vertex_begin.end()))
    throw InternalError("scene topology: the part layout does not cover the mesh");
  for (PartCheck& c : checks) {
    if (c.a > c.b) std::swap(c.a, c.b);
    if (c.a < 0 || c.b >= parts)
      throw InternalError("scene topology: a check of part " + std::to_string(c.b) + " of " +
                          std::to_string(parts));
  }
  std::sort(checks.begin(), checks.end());
  checks.erase(std::unique(checks.begin(), checks.end()), checks.end());
  for (int32_t p = 0; p < parts; ++p)
    for (int32_t t = layout.triangle_begin[p]; t < layout.triangle_begin[p + 1]; ++t)
      for (int k = 0; k < 3; ++k) {
        const int32_t v = triangles[t].v[k];
        if (v >= 0 && v < vertex_count &&
            (v < layout.vertex_begin[p] || v >= layout.vertex_begin[p + 1]))
          throw InternalError("scene topology: triangle " + std::to_string(t) + " of part " +
                              std::to_string(p) + " uses vertex " + std::to_string(v) +
                              " of another part");
      }

  Topology topo;
  topo.layout = std::move(layout);
  topo.checks = std::move(checks);
  topo.triangles.assign(triangles.begin(), triangles.end());
  topo.vertex_count = vertex_count;
  const auto n = static_cast<int32_t>(triangles.size());
  topo.triangle_edges.assign(static_cast<size_t>(n), {-1, -1, -1});
  topo.owned_edges.assign(static_cast<size_t>(n), 0);

  // The edges' records grouped by their smaller endpoint (a counting sort, stable: each
  // group in increasing triangle id), then each small group ordered by the larger endpoint
  // (insertion sort, stable): records in (u, v, triangle) order in linear time. Every array
  // is sized once: a first topology's time is mostly the first touch of its pages (on the
  // 2-core EPYC VM ~36 of a 36K cloth's ~41 ms, before the records were placed without a copy
  // and the edge lists sized ahead).
  // A repeated corner: zero area in every frame, left out of the search, owns nothing.
  auto repeats_a_corner = [](const geom::Tri& tri) {
    return tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[2] == tri.v[0];
  };
  std::vector<int32_t> group_begin(static_cast<size_t>(vertex_count) + 1, 0);
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri& tri = triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri.v[k] < 0 || tri.v[k] >= vertex_count)
        throw InternalError("triangle " + std::to_string(t) + " uses vertex " +
                            std::to_string(tri.v[k]) + " of " + std::to_string(vertex_count));
    if (repeats_a_corner(tri)) {
      topo.index_degenerate.push_back(t);
      continue;
    }
    for (int k = 0; k < 3; ++k) ++group_begin[std::min(tri.v[k], tri.v[(k + 1) % 3]) + 1];
  }
  for (int32_t v = 0; v < vertex_count; ++v) group_begin[v + 1] += group_begin[v];
  std::vector<EdgeRecord> records(static_cast<size_t>(group_begin.back()));
  {
    std::vector<int32_t> fill(group_begin.begin(), group_begin.end() - 1);
    for (int32_t t = 0; t < n; ++t) {
      const geom::Tri& tri = triangles[t];
      if (repeats_a_corner(tri)) continue;
      for (int k = 0; k < 3; ++k) {
        const int32_t a = tri.v[k], b = tri.v[(k + 1) % 3];
        records[fill[std::min(a, b)]++] = {std::min(a, b), std::max(a, b), t, k};
      }
    }
  }
  for (int32_t u = 0; u < vertex_count; ++u)
    for (int32_t r = group_begin[u] + 1; r < group_begin[u + 1]; ++r) {
      const EdgeRecord rec = records[r];
      int32_t to = r;
      for (; to > group_begin[u] && records[to - 1].v > rec.v; --to) records[to] = records[to - 1];
      records[to] = rec;
    }

  // Whether record r is its edge's first (records of one edge are adjacent).
  auto starts_edge = [&](size_t r) {
    return r == 0 || records[r].u != records[r - 1].u || records[r].v != records[r - 1].v;
  };
  size_t edge_count = 0;
  for (size_t r = 0; r < records.size(); ++r) edge_count += starts_edge(r);
  topo.edges.reserve(edge_count);
  topo.edge_face_offsets.reserve(edge_count + 1);
  topo.edge_faces.reserve(records.size());
  topo.edge_face_offsets.push_back(0);
  for (size_t r = 0; r < records.size(); ++r) {
    const EdgeRecord& rec = records[r];
    if (starts_edge(r)) {
      if (r > 0) topo.edge_face_offsets.push_back(static_cast<int32_t>(topo.edge_faces.size()));
      topo.edges.push_back({rec.u, rec.v});
      // Records of one edge are sorted by triangle: the first is the representative.
      topo.owned_edges[rec.triangle] |= static_cast<uint8_t>(1u << rec.corner);
    }
    const auto edge = static_cast<int32_t>(topo.edges.size() - 1);
    topo.triangle_edges[rec.triangle][rec.corner] = edge;
    topo.edge_faces.push_back(rec.triangle);
  }
  if (!records.empty())
    topo.edge_face_offsets.push_back(static_cast<int32_t>(topo.edge_faces.size()));
  make_neighbor_pairs(topo);
  select_self_neighbors(topo);
  return topo;
}

std::vector<uint8_t> ownership_without(const Topology& topo, std::span<const int32_t> degenerate) {
  std::vector<uint8_t> owned = topo.owned_edges;
  if (degenerate.empty()) return owned;
  auto is_degenerate = [&](int32_t t) {
    return std::binary_search(degenerate.begin(), degenerate.end(), t);
  };
  for (int32_t d : degenerate) {
    for (int k = 0; k < 3; ++k) {
      if (!(owned[d] & (1u << k))) continue;
      owned[d] &= static_cast<uint8_t>(~(1u << k));
      const int32_t edge = topo.triangle_edges[d][k];
      for (int32_t i = topo.edge_face_offsets[edge]; i < topo.edge_face_offsets[edge + 1]; ++i) {
        const int32_t f = topo.edge_faces[i];
        if (f == d || is_degenerate(f)) continue;
        for (int kk = 0; kk < 3; ++kk)
          if (topo.triangle_edges[f][kk] == edge) owned[f] |= static_cast<uint8_t>(1u << kk);
        break;
      }
    }
  }
  return owned;
}

}  // namespace snag::detect
