#include "snag/validators/cgal_reference.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <string>

#include "snag/error.h"

namespace snag::validators {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

Point point_of(const geom::Vec3d& p) {
  return {p.x, p.y, p.z};
}

bool degenerate(std::span<const geom::Vec3d> positions, const geom::Tri& t) {
  return CGAL::collinear(point_of(positions[t.v[0]]), point_of(positions[t.v[1]]),
                         point_of(positions[t.v[2]]));
}

void sort_pairs(std::vector<std::pair<int32_t, int32_t>>& pairs) {
  for (auto& [a, b] : pairs)
    if (a > b) std::swap(a, b);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}

using Box =
    CGAL::Box_intersection_d::Box_with_info_d<double, 3, int32_t,
                                              CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;

/// The boxes of the triangles that are not zero-area, each carrying its triangle's id.
std::vector<Box> boxes_of(std::span<const geom::Vec3d> positions,
                          std::span<const geom::Tri> triangles) {
  std::vector<Box> boxes;
  boxes.reserve(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const geom::Tri& tri = triangles[t];
    if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[2] == tri.v[0] ||
        degenerate(positions, tri))
      continue;
    const auto box = point_of(positions[tri.v[0]]).bbox() + point_of(positions[tri.v[1]]).bbox() +
                     point_of(positions[tri.v[2]]).bbox();
    boxes.emplace_back(box, static_cast<int32_t>(t));
  }
  return boxes;
}

std::vector<const Box*> pointers_to(const std::vector<Box>& boxes) {
  std::vector<const Box*> pointers;
  pointers.reserve(boxes.size());
  for (const Box& b : boxes) pointers.push_back(&b);
  return pointers;
}

}  // namespace

std::vector<std::pair<int32_t, int32_t>> pair_ids(std::span<const detect::FacePair> pairs) {
  std::vector<std::pair<int32_t, int32_t>> ids;
  ids.reserve(pairs.size());
  for (const detect::FacePair& p : pairs) ids.emplace_back(p.a, p.b);
  return ids;
}

bool cgal_faces_intersect(std::span<const geom::Vec3d> positions, const geom::Tri& f,
                          const geom::Tri& g) {
  int shared = 0, fi = -1, gi = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (f.v[i] == g.v[j]) {
        if (shared == 0) fi = i, gi = j;
        ++shared;
      }
  auto P = [&](int32_t v) { return point_of(positions[v]); };
  if (shared == 3) return true;  // a duplicated face overlaps beyond each of its edges
  if (shared == 2) {
    // The faces' third vertices; the shared edge is the other two.
    int f_third = 0, g_third = 0;
    for (int i = 0; i < 3; ++i) {
      if (f.v[i] != g.v[0] && f.v[i] != g.v[1] && f.v[i] != g.v[2]) f_third = i;
      if (g.v[i] != f.v[0] && g.v[i] != f.v[1] && g.v[i] != f.v[2]) g_third = i;
    }
    const Point p = P(f.v[(f_third + 1) % 3]), q = P(f.v[(f_third + 2) % 3]);
    const Point r = P(f.v[f_third]), s = P(g.v[g_third]);
    return CGAL::coplanar(p, q, r, s) && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
  }
  const Kernel::Triangle_3 tf(P(f.v[0]), P(f.v[1]), P(f.v[2])), tg(P(g.v[0]), P(g.v[1]), P(g.v[2]));
  if (shared == 1) {
    const Kernel::Segment_3 sf(P(f.v[(fi + 1) % 3]), P(f.v[(fi + 2) % 3]));
    const Kernel::Segment_3 sg(P(g.v[(gi + 1) % 3]), P(g.v[(gi + 2) % 3]));
    return CGAL::do_intersect(tf, sg) || CGAL::do_intersect(tg, sf);
  }
  return CGAL::do_intersect(tf, tg);
}

detect::PairKind cgal_pair_kind(std::span<const geom::Vec3d> positions, const geom::Tri& f,
                                const geom::Tri& g) {
  auto P = [&](int32_t v) { return point_of(positions[v]); };
  // Each triangle has corners strictly on both sides of the other's plane (which also rules
  // out coplanar pairs).
  auto straddles = [&](const geom::Tri& t, const geom::Tri& plane) {
    bool positive = false, negative = false;
    for (int i = 0; i < 3; ++i) {
      const CGAL::Orientation o =
          CGAL::orientation(P(plane.v[0]), P(plane.v[1]), P(plane.v[2]), P(t.v[i]));
      positive |= o == CGAL::POSITIVE;
      negative |= o == CGAL::NEGATIVE;
    }
    return positive && negative;
  };
  if (!straddles(f, g) || !straddles(g, f)) return detect::PairKind::touching;
  // Then each meets the other's plane in a segment on the planes' common line, and the pair
  // crosses when the two segments overlap in more than a point: CGAL constructs the
  // intersection exactly.
  using Exact = CGAL::Exact_predicates_exact_constructions_kernel;
  auto E = [&](int32_t v) {
    return Exact::Point_3(positions[v].x, positions[v].y, positions[v].z);
  };
  const Exact::Triangle_3 tf(E(f.v[0]), E(f.v[1]), E(f.v[2])), tg(E(g.v[0]), E(g.v[1]), E(g.v[2]));
  const auto meet = CGAL::intersection(tf, tg);
  if (!meet) return detect::PairKind::touching;
  const auto* segment = boost::get<Exact::Segment_3>(&*meet);
  return segment && !segment->is_degenerate() ? detect::PairKind::crossing
                                              : detect::PairKind::touching;
}

struct CgalSequence::State {
  Mesh mesh;
  std::vector<int32_t> triangle_of_face;
};

CgalSequence::CgalSequence(std::span<const geom::Vec3d> positions,
                           std::span<const geom::Tri> triangles)
    : state_(std::make_unique<State>()) {
  Mesh& mesh = state_->mesh;
  for (const geom::Vec3d& p : positions) mesh.add_vertex(point_of(p));
  for (size_t t = 0; t < triangles.size(); ++t) {
    const geom::Tri& tri = triangles[t];
    if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[2] == tri.v[0] ||
        degenerate(positions, tri))
      continue;
    const auto face = mesh.add_face(Mesh::Vertex_index(tri.v[0]), Mesh::Vertex_index(tri.v[1]),
                                    Mesh::Vertex_index(tri.v[2]));
    if (face == Mesh::null_face())
      throw InternalError("triangle " + std::to_string(t) +
                          " cannot join CGAL's halfedge mesh (non-manifold or "
                          "inconsistently oriented)");
    state_->triangle_of_face.push_back(static_cast<int32_t>(t));
  }
}

CgalSequence::~CgalSequence() = default;

void CgalSequence::set_positions(std::span<const geom::Vec3d> positions) {
  Mesh& mesh = state_->mesh;
  for (size_t v = 0; v < positions.size(); ++v)
    mesh.point(Mesh::Vertex_index(static_cast<uint32_t>(v))) = point_of(positions[v]);
}

std::vector<std::pair<int32_t, int32_t>> CgalSequence::self_intersections() const {
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> found;
  CGAL::Polygon_mesh_processing::self_intersections<CGAL::Sequential_tag>(
      state_->mesh, std::back_inserter(found));
  std::vector<std::pair<int32_t, int32_t>> pairs;
  pairs.reserve(found.size());
  for (const auto& [f, g] : found)
    pairs.emplace_back(state_->triangle_of_face[f.idx()], state_->triangle_of_face[g.idx()]);
  sort_pairs(pairs);
  return pairs;
}

std::vector<std::pair<int32_t, int32_t>> cgal_self_intersections(
    std::span<const geom::Vec3d> positions, std::span<const geom::Tri> triangles) {
  return CgalSequence(positions, triangles).self_intersections();
}

std::vector<std::pair<int32_t, int32_t>> cgal_soup_self_intersections(
    std::span<const geom::Vec3d> positions, std::span<const geom::Tri> triangles) {
  const std::vector<Box> boxes = boxes_of(positions, triangles);
  std::vector<const Box*> pointers = pointers_to(boxes);
  std::vector<std::pair<int32_t, int32_t>> pairs;
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(
      pointers.begin(), pointers.end(), [&](const Box* a, const Box* b) {
        if (cgal_faces_intersect(positions, triangles[a->info()], triangles[b->info()]))
          pairs.emplace_back(a->info(), b->info());
      });
  sort_pairs(pairs);
  return pairs;
}

std::vector<std::pair<int32_t, int32_t>> cgal_pairs_between(
    std::span<const geom::Vec3d> positions_a, std::span<const geom::Tri> triangles_a,
    std::span<const geom::Vec3d> positions_b, std::span<const geom::Tri> triangles_b) {
  const std::vector<Box> boxes_a = boxes_of(positions_a, triangles_a);
  const std::vector<Box> boxes_b = boxes_of(positions_b, triangles_b);
  std::vector<const Box*> pointers_a = pointers_to(boxes_a), pointers_b = pointers_to(boxes_b);
  auto triangle = [](std::span<const geom::Vec3d> positions, const geom::Tri& t) {
    return Kernel::Triangle_3(point_of(positions[t.v[0]]), point_of(positions[t.v[1]]),
                              point_of(positions[t.v[2]]));
  };
  std::vector<std::pair<int32_t, int32_t>> pairs;
  // The bipartite form calls back with a box of the first sequence first. The meshes share no
  // vertex, so any common point counts: plain do_intersect, no shared-vertex rules.
  CGAL::box_intersection_d<CGAL::Sequential_tag>(
      pointers_a.begin(), pointers_a.end(), pointers_b.begin(), pointers_b.end(),
      [&](const Box* a, const Box* b) {
        if (CGAL::do_intersect(triangle(positions_a, triangles_a[a->info()]),
                               triangle(positions_b, triangles_b[b->info()])))
          pairs.emplace_back(a->info(), b->info());
      });
  // Not sort_pairs: (i, j) index two different meshes, so i > j must not be swapped.
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace snag::validators
