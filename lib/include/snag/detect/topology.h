// What is fixed per topology: triangles, unique edges, which triangles use each edge, and the
// representative-triangle ownership of edges (Curtis, Tamstorf and Manocha 2008).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "snag/geom/vec3.h"

namespace snag::detect {

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

  int32_t triangle_count() const { return static_cast<int32_t>(triangles.size()); }
};

Topology make_topology(std::span<const geom::Tri> triangles, int32_t vertex_count);

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
