// A triangle mesh as read from one frame file, with the ids users see.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "snag/geom/vec3.h"

namespace snag::mesh {

/// One frame's mesh. Vertex ids are positions' indices, triangle ids are triangles' indices;
/// both are the file's (0-based, file order). A polygon of k > 3 corners becomes k - 2
/// triangles (a fan from its first corner) that share its polygon id.
struct Mesh {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
  std::vector<int32_t> source_polygon;   ///< per triangle: the file's face (polygon) id
  std::vector<int32_t> triangle_group;   ///< per triangle: index into group_names, or -1
  std::vector<std::string> group_names;  ///< OBJ `o`/`g` names in order of first use
  int64_t polygon_count = 0;             ///< faces as listed in the file
  bool ids_from_assimp = false;          ///< true when ids are assimp's, not the file's
};

/// Non-owning view passed by value into kernels and OpenMP loops alike.
struct MeshView {
  const geom::Vec3d* positions = nullptr;
  const geom::Tri* triangles = nullptr;
  int32_t vertex_count = 0;
  int32_t triangle_count = 0;
};

inline MeshView view_of(const std::vector<geom::Vec3d>& positions,
                        const std::vector<geom::Tri>& triangles) {
  return {positions.data(), triangles.data(), static_cast<int32_t>(positions.size()),
          static_cast<int32_t>(triangles.size())};
}

}  // namespace snag::mesh
