// Scenes for the tests: small meshes laid end to end as the parts of one topology, and the
// brute-force reference of a scene (the whole mesh's pairs, kept to the checks asked for).
#pragma once

#include <vector>

#include "detect_cases.h"
#include "snag/detect/topology.h"

namespace snag::test {

/// Meshes laid end to end: vertex ids of each shifted past the earlier ones'.
struct Laid {
  SmallMesh mesh;
  detect::PartLayout layout;
};

inline Laid lay_end_to_end(const std::vector<SmallMesh>& parts) {
  Laid laid;
  laid.layout.triangle_begin = {0};
  laid.layout.vertex_begin = {0};
  for (const SmallMesh& part : parts) {
    const auto base = static_cast<int32_t>(laid.mesh.positions.size());
    laid.mesh.positions.insert(laid.mesh.positions.end(), part.positions.begin(),
                               part.positions.end());
    for (geom::Tri t : part.triangles) {
      for (int k = 0; k < 3; ++k) t.v[k] += base;
      laid.mesh.triangles.push_back(t);
    }
    laid.layout.triangle_begin.push_back(static_cast<int32_t>(laid.mesh.triangles.size()));
    laid.layout.vertex_begin.push_back(static_cast<int32_t>(laid.mesh.positions.size()));
  }
  return laid;
}

inline int32_t part_of(const detect::PartLayout& layout, int32_t t) {
  int32_t p = 0;
  while (t >= layout.triangle_begin[p + 1]) ++p;
  return p;
}

/// Scenes with a part that has no triangles (an obstacle file without faces), no vertices or a
/// few, first, between or last; the last scene has nothing else. Checked with every part pair.
inline std::vector<Laid> scenes_with_an_empty_part() {
  const SmallMesh cloth = folded_grid(12, 5), body = lattice_soup(40, 30, 4, 2);
  SmallMesh nothing, points;
  points.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  return {lay_end_to_end({cloth, nothing, body}), lay_end_to_end({cloth, points}),
          lay_end_to_end({nothing, cloth}), lay_end_to_end({points})};
}

/// Every pair of a scene's parts, itself included.
inline std::vector<detect::PartCheck> every_check(const Laid& laid) {
  std::vector<detect::PartCheck> checks;
  for (int32_t a = 0; a < laid.layout.part_count(); ++a)
    for (int32_t b = a; b < laid.layout.part_count(); ++b) checks.push_back({a, b});
  return checks;
}

/// The brute-force pairs of the whole mesh whose parts are checked together.
inline std::vector<detect::FacePair> expected_pairs(const Laid& laid,
                                                    const std::vector<detect::PartCheck>& checks) {
  std::vector<detect::FacePair> kept;
  for (const detect::FacePair& p : brute_force(laid.mesh)) {
    int32_t a = part_of(laid.layout, p.a), b = part_of(laid.layout, p.b);
    if (a > b) std::swap(a, b);
    for (const detect::PartCheck& c : checks)
      if (c.a == a && c.b == b) {
        kept.push_back(p);
        break;
      }
  }
  return kept;
}

}  // namespace snag::test
