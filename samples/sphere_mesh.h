// A triangulated sphere, written next to the cloth as the obstacle it drapes over.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace snag::samples {

struct TriangleMesh {
  Eigen::Matrix3Xd positions;                 // 3 x vertex count
  std::vector<std::array<int, 3>> triangles;  // 0-based, counter-clockwise seen from outside
};

// A latitude-longitude sphere: `segments` vertices around each of `segments / 2 - 1` rings plus
// the two poles, 2 * segments * (segments / 2 - 1) triangles. Its vertices lie on the sphere, so
// the mesh is inside it; the cloth is kept `contact_offset` outside, which clears the flat faces
// as long as that offset exceeds the faces' sagitta (r (1 - cos(pi / segments)), 0.0024 for
// r = 0.5 and 32 segments). Throws std::invalid_argument when `segments` < 4.
[[nodiscard]] TriangleMesh make_sphere(const Eigen::Vector3d& center, double radius, int segments);

}  // namespace snag::samples
