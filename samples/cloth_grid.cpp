#include "cloth_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snag::samples {

GridSize grid_for_triangles(std::int64_t triangles) {
  if (triangles < 2) {
    throw std::invalid_argument("--triangles must be at least 2, got " + std::to_string(triangles));
  }
  // Candidates are n x n and n x (n + 1) for n around sqrt(T / 2); the two shapes interleave in
  // size, so checking a few n on both sides of the root finds the closest one.
  const auto root = static_cast<std::int64_t>(std::sqrt(double(triangles) / 2.0));
  GridSize best{1, 1};
  std::int64_t best_error = -1;
  for (std::int64_t n = std::max<std::int64_t>(1, root - 2); n <= root + 2; ++n) {
    for (std::int64_t extra = 0; extra <= 1; ++extra) {
      const std::int64_t count = 2 * n * (n + extra);
      const std::int64_t error = count > triangles ? count - triangles : triangles - count;
      if (best_error < 0 || error < best_error) {
        best_error = error;
        best = GridSize{int(n), int(n + extra)};
      }
    }
  }
  return best;
}

std::vector<std::array<int, 3>> grid_triangles(GridSize grid) {
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(std::size_t(grid.triangle_count()));
  for (int j = 0; j < grid.ny; ++j) {
    for (int i = 0; i < grid.nx; ++i) {
      const int v00 = grid.vertex(i, j);
      const int v10 = grid.vertex(i + 1, j);
      const int v01 = grid.vertex(i, j + 1);
      const int v11 = grid.vertex(i + 1, j + 1);
      // Each triangle starts with an edge along +z and turns towards +x: (+z) x (+x) = +y.
      if ((i + j) % 2 == 0) {
        triangles.push_back({v00, v01, v11});
        triangles.push_back({v00, v11, v10});
      } else {
        triangles.push_back({v00, v01, v10});
        triangles.push_back({v10, v01, v11});
      }
    }
  }
  return triangles;
}

}  // namespace snag::samples
