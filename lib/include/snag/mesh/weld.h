// Welding for adjacency: which vertices count as one when triangles' shared corners are found.
// Positions and ids are never changed; only the adjacency computed from the result is.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "snag/geom/vec3.h"

namespace snag::mesh {

/// For each vertex, the id of its representative: the smallest id of its cluster, where two
/// vertices are in one cluster when a chain of vertices links them, each step no longer than
/// `tolerance` (Euclidean distance <= tolerance; 0 joins exactly equal positions only).
/// The result has positions.size() entries, rep[i] <= i, rep[rep[i]] == rep[i], and does not
/// depend on thread count or hashing order. Positions must be finite. Throws snag::UsageError
/// when `tolerance` is negative or not finite. O(n log n) with a uniform grid of cell 2*tol.
std::vector<int32_t> weld_representatives(std::span<const geom::Vec3d> positions, double tolerance);

/// The triangles with every corner replaced by its representative (weld_representatives), which
/// is how welding joins triangles for adjacency; `representative` empty: the triangles as they are.
std::vector<geom::Tri> welded_triangles(std::span<const geom::Tri> triangles,
                                        std::span<const int32_t> representative);

/// The number of vertices whose position exactly equals that of a vertex with a smaller id
/// (what `--weld` would join at tolerance 0); 0 for a mesh without coincident vertices.
int64_t count_coincident_vertices(std::span<const geom::Vec3d> positions);

}  // namespace snag::mesh
