// Runs the whole check (CPU backend, checker) on a small mesh, with an exact resolver.
#pragma once

#include <memory>
#include <vector>

#include "exact_integer.h"
#include "snag/detect/checker.h"
#include "snag/detect/cpu_backend.h"

namespace snag::test {

struct SmallMesh {
  std::vector<geom::Vec3d> positions;
  std::vector<geom::Tri> triangles;
};

inline detect::FrameResult check_mesh(
    const SmallMesh& mesh, int threads = 2,
    std::shared_ptr<detect::ExactResolver> resolver = nullptr,
    detect::CpuWalkWidth width = detect::CpuWalkWidth::automatic) {
  if (!resolver) resolver = std::make_shared<IntegerResolver>();
  detect::Checker checker(detect::make_cpu_backend(threads, width), resolver);
  checker.set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
  return checker.check(mesh.positions);
}

/// An integer affine map x -> M x + t with det M != 0: it keeps every incidence, so every
/// answer, while moving the input off the coordinate planes where the filter decides alone.
inline SmallMesh transformed(SmallMesh mesh, const int m[3][3], geom::Vec3d t) {
  for (auto& p : mesh.positions) {
    const geom::Vec3d q = p;
    p = {m[0][0] * q.x + m[0][1] * q.y + m[0][2] * q.z + t.x,
         m[1][0] * q.x + m[1][1] * q.y + m[1][2] * q.z + t.y,
         m[2][0] * q.x + m[2][1] * q.y + m[2][2] * q.z + t.z};
  }
  return mesh;
}

}  // namespace snag::test
