#include "sphere_mesh.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace snag::samples {

TriangleMesh make_sphere(const Eigen::Vector3d& center, double radius, int segments) {
  if (segments < 4) {
    throw std::invalid_argument("the sphere needs at least 4 segments, got " +
                                std::to_string(segments));
  }
  const int rings = segments / 2 - 1;  // latitude circles between the poles
  TriangleMesh mesh;
  mesh.positions.resize(3, 2 + Eigen::Index(rings) * segments);
  const int north = 0;
  const int south = 1 + rings * segments;
  mesh.positions.col(north) = center + Eigen::Vector3d(0.0, radius, 0.0);
  mesh.positions.col(south) = center - Eigen::Vector3d(0.0, radius, 0.0);
  const auto ring_vertex = [&](int ring, int k) { return 1 + ring * segments + k % segments; };
  for (int ring = 0; ring < rings; ++ring) {
    const double polar = std::numbers::pi * (ring + 1) / (rings + 1);
    for (int k = 0; k < segments; ++k) {
      const double azimuth = 2.0 * std::numbers::pi * k / segments;
      mesh.positions.col(ring_vertex(ring, k)) =
          center + radius * Eigen::Vector3d(std::sin(polar) * std::cos(azimuth), std::cos(polar),
                                            std::sin(polar) * std::sin(azimuth));
    }
  }
  // Azimuth grows from +x towards +z, i.e. clockwise seen from above, so outward-facing
  // counter-clockwise triangles go (upper, next, lower) in that order below.
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.push_back({north, ring_vertex(0, k + 1), ring_vertex(0, k)});
  }
  for (int ring = 0; ring + 1 < rings; ++ring) {
    for (int k = 0; k < segments; ++k) {
      const int a = ring_vertex(ring, k);
      const int b = ring_vertex(ring, k + 1);
      const int c = ring_vertex(ring + 1, k);
      const int d = ring_vertex(ring + 1, k + 1);
      mesh.triangles.push_back({a, b, d});
      mesh.triangles.push_back({a, d, c});
    }
  }
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.push_back({south, ring_vertex(rings - 1, k), ring_vertex(rings - 1, k + 1)});
  }
  return mesh;
}

}  // namespace snag::samples
