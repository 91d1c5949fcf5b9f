// What is fixed per topology: triangles, unique edges, which triangles use each edge, the
// representative-triangle ownership of edges (Curtis, Tamstorf and Manocha 2008), and for a
// scene of several objects, which triangles are whose and which objects are checked together.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "snag/geom/vec3.h"

namespace snag::detect {

/// A scene's objects as the checker sees them ("parts"): laid end to end in one mesh, part p
/// owning triangles [triangle_begin[p], triangle_begin[p + 1]) and vertices
/// [vertex_begin[p], vertex_begin[p + 1]). Parts share no vertex: faces of two objects share no
/// topology. A single mesh is one part.
struct PartLayout {
  std::vector<int32_t> triangle_begin = {0, 0};  ///< part count + 1 entries, non-decreasing
  std::vector<int32_t> vertex_begin = {0, 0};
  int32_t part_count() const { return static_cast<int32_t>(triangle_begin.size()) - 1; }
  /// The part triangle t is in.
  int32_t part_of(int32_t t) const;
};

/// Two parts checked against each other, a <= b; a == b checks the part's self-intersections.
struct PartCheck {
  int32_t a = 0;
  int32_t b = 0;
  bool self() const { return a == b; }
  /// Ordered by (a, b), the order of Topology::checks.
  friend auto operator<=>(const PartCheck&, const PartCheck&) = default;
};

/// One step around a vertex v's fan (Topology::fan_steps): the fan's triangles t_0, t_1, ... in
/// order around v, t_i = (v, a_i, a_{i+1}) sharing the edge (v, a_{i+1}) with t_{i+1}.
struct FanStep {
  int32_t corner;  ///< a_i
  /// 2 t_i, plus 1 when t_i's corners run (v, a_{i+1}, a_i) rather than (v, a_i, a_{i+1}) in
  /// its own cyclic order (its plane's normal then points against the fan's); -1 on the last
  /// step of an open fan, which only closes the last triangle with its corner a_k.
  int32_t face;
};

/// Edge k of a triangle joins corners k and (k + 1) % 3.
struct Topology {
  std::vector<geom::Tri> triangles;
  int32_t vertex_count = 0;
  /// Unique undirected edges, endpoints in increasing vertex id.
  std::vector<std::array<int32_t, 2>> edges;
  /// Per triangle, the edge id of each of its three edges; -1 where two corners repeat an index.
  std::vector<std::array<int32_t, 3>> triangle_edges;
  /// Incident triangles of edge e, in increasing id: edge_faces[edge_face_offsets[e] ..
  /// edge_face_offsets[e + 1]).
  std::vector<int32_t> edge_face_offsets;
  std::vector<int32_t> edge_faces;
  /// Per triangle, bit k set when the triangle owns its edge k: each edge is owned by its
  /// incident triangle of smallest id, so each (edge, triangle) test is done by one triangle.
  /// Frames with degenerate triangles hand their edges to the next incident triangle.
  std::vector<uint8_t> owned_edges;
  /// Triangles whose corners repeat a vertex id: degenerate in every frame.
  std::vector<int32_t> index_degenerate;
  /// Neighbour pairs (a < b, sorted): triangles sharing a listed vertex. They make most of the
  /// candidates in a mesh (about 7 per triangle in a cloth) and never change with the frame,
  /// so they are tested in a pass over this list and skipped by the traversal. A vertex is
  /// listed when at most kMaxListedValence triangles use it, which bounds the list by
  /// kMaxListedValence^2 / 2 pairs per vertex; pairs around larger fans stay with the traversal.
  std::vector<std::array<int32_t, 2>> neighbor_pairs;
  /// Per neighbour pair (a, b): bits 0-2 mark the corners of a that are vertices of b, bits
  /// 3-5 the corners of b that are vertices of a (shared_corners, fixed with the topology).
  std::vector<uint8_t> neighbor_shared;
  std::vector<uint8_t> listed_vertex;  ///< per vertex: 1 when its fan's pairs are listed
  bool every_vertex_listed = true;
  static constexpr int32_t kMaxListedValence = 32;
  /// Fans (see detect/fan.h): for a listed vertex v of a part checked against itself whose
  /// triangles (those not repeating a corner) form one strip around it, each sharing an
  /// edge with the next and every such edge shared by two of them, fan_steps[fan_begin[v] ..
  /// fan_begin[v + 1]) walks around it: k steps for a closed fan of k >= 3 triangles (an
  /// interior vertex), k + 1 for an open one of k >= 2 (a border vertex). Other vertices have
  /// no steps. The walk starts at the smallest triangle (an open fan: at its end whose
  /// first triangle has the smaller id) and goes on across t_0's edge after v in t_0's order.
  std::vector<int32_t> fan_begin;  ///< vertex_count + 1 offsets
  std::vector<FanStep> fan_steps;

  /// Triangle t's neighbour pairs (t, x), x > t: neighbor_pairs[neighbor_begin[t] ..
  /// neighbor_begin[t + 1]) (triangle_count + 1 offsets). A part's triangles being
  /// contiguous, so are its pairs; a part not checked against itself has none listed.
  std::vector<int64_t> neighbor_begin;

  /// The parts (one for a single mesh) and the checks between them, in increasing (a, b).
  /// Neighbour pairs never join two parts (they share no vertex).
  PartLayout layout;
  std::vector<PartCheck> checks = {PartCheck{}};

  int32_t triangle_count() const { return static_cast<int32_t>(triangles.size()); }
  int32_t part_count() const { return layout.part_count(); }
  /// The part triangle t belongs to.
  int32_t part_of(int32_t t) const;
};

/// The topology of one mesh: one part, checked against itself.
Topology make_topology(std::span<const geom::Tri> triangles, int32_t vertex_count);

/// The topology of a scene: `triangles` and the vertex count of every part laid end to end as
/// `layout` says, and the part pairs to check. Throws InternalError for a layout that does not
/// cover the triangles and vertices, a triangle using another part's vertex, or a check of a
/// part that does not exist.
Topology make_scene_topology(std::span<const geom::Tri> triangles, int32_t vertex_count,
                             PartLayout layout, std::vector<PartCheck> checks);

/// The ownership masks for a frame whose degenerate triangles (sorted ids) own nothing: each
/// edge goes to its smallest non-degenerate incident triangle.
std::vector<uint8_t> ownership_without(const Topology& topology,
                                       std::span<const int32_t> degenerate);

/// Non-owning view for the narrow phase (host and device).
struct TopologyView {
  const geom::Tri* triangles = nullptr;
  const std::array<int32_t, 2>* edges = nullptr;
  const std::array<int32_t, 3>* triangle_edges = nullptr;
  const uint8_t* owned_edges = nullptr;
  const uint8_t* listed_vertex = nullptr;
  bool every_vertex_listed = true;
  int32_t triangle_count = 0;
  int32_t edge_count = 0;
};

}  // namespace snag::detect
