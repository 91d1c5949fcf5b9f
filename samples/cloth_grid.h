// The cloth's grid: sizes, vertex numbering and triangulation.
//
// A grid of nx by ny quads has (nx + 1) * (ny + 1) vertices, numbered row by row:
// vertex (i, j), 0 <= i <= nx along x and 0 <= j <= ny along z, is i + j * (nx + 1).
// Each quad is split into 2 triangles, so the cloth has 2 * nx * ny triangles.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace snag::samples {

struct GridSize {
  int nx = 0;  // quads along x
  int ny = 0;  // quads along z

  [[nodiscard]] std::int64_t vertex_count() const { return std::int64_t(nx + 1) * (ny + 1); }
  [[nodiscard]] std::int64_t triangle_count() const { return 2 * std::int64_t(nx) * ny; }
  [[nodiscard]] int vertex(int i, int j) const { return i + j * (nx + 1); }
};

// The near-square grid (nx == ny or nx + 1 == ny) whose triangle count is closest to `triangles`
// (ties go to the smaller grid). Throws std::invalid_argument when `triangles` < 2.
// The paper's sizes: 2,244 -> 33 x 34 (2,244 exactly), 27,030 -> 116 x 117 (27,144),
// 35,992 -> 134 x 134 (35,912).
[[nodiscard]] GridSize grid_for_triangles(std::int64_t triangles);

// The 2 * nx * ny triangles, 0-based vertex ids, counter-clockwise seen from +y (the cloth's
// normal points up before it falls). Quads are listed row by row, the two triangles of a quad
// one after the other. The diagonal alternates in a checkerboard so that the grid has no
// preferred shear direction, which would otherwise make every fold lean the same way.
[[nodiscard]] std::vector<std::array<int, 3>> grid_triangles(GridSize grid);

}  // namespace snag::samples
