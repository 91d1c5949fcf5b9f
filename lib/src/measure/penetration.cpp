#include "snag/measure/penetration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "snag/error.h"
#include "snag/mesh/mesh.h"
#include "snag/threads.h"

namespace snag::measure {

namespace {

// ---------------------------------------------------------------------------------------------
// Topology: closedness, the triangle across each edge, the corners around each vertex.

/// One triangle's use of an undirected edge (lo < hi), from corner `corner` to the next.
struct HalfEdge {
  int32_t lo, hi;
  int32_t triangle;
  int32_t corner;
  bool forward;  ///< the triangle walks it from lo to hi
};

/// What the meter keeps of the topology. across: 3 per triangle; corner_begin / corners: the
/// corners (3 t + k) of each vertex, CSR.
struct Adjacency {
  std::vector<int32_t> across;
  std::vector<int32_t> corner_begin;
  std::vector<int32_t> corners;
};

std::string edge_name(int32_t lo, int32_t hi) {
  std::string s = "edge (";
  s.append(std::to_string(lo)).append(", ").append(std::to_string(hi)).append(")");
  return s;
}

int32_t find_root(std::vector<int32_t>& parent, int32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

/// The checks of why_not_closed; fills `out` when the surface is closed.
std::optional<std::string> analyse(std::span<const geom::Tri> triangles, int32_t vertex_count,
                                   Adjacency& out) {
  if (triangles.empty()) return "no triangles: an empty surface encloses nothing";
  if (triangles.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max() / 3))
    return std::to_string(triangles.size()) + " triangles: more than snag's 32-bit ids allow";
  const auto n = static_cast<int32_t>(triangles.size());
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri& tri = triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri.v[k] < 0 || tri.v[k] >= vertex_count) {
        std::string s = "triangle " + std::to_string(t);
        s.append(" has vertex ").append(std::to_string(tri.v[k]));
        s.append(", expected one in [0, ").append(std::to_string(vertex_count)).append(")");
        return s;
      }
    for (int k = 0; k < 3; ++k)
      if (tri.v[k] == tri.v[(k + 1) % 3]) {
        std::string s = "triangle " + std::to_string(t);
        s.append(" repeats vertex ").append(std::to_string(tri.v[k]));
        return s;
      }
  }

  std::vector<HalfEdge> edges;
  edges.reserve(3 * static_cast<size_t>(n));
  for (int32_t t = 0; t < n; ++t)
    for (int32_t k = 0; k < 3; ++k) {
      const int32_t a = triangles[t].v[k], b = triangles[t].v[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), t, k, a < b});
    }
  std::sort(edges.begin(), edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    return x.triangle != y.triangle ? x.triangle < y.triangle : x.corner < y.corner;
  });

  out.across.assign(3 * static_cast<size_t>(n), -1);
  // Corners of one vertex are joined when their triangles share an edge at that vertex; a
  // vertex whose corners end in more than one set is a pinch point.
  std::vector<int32_t> parent(3 * static_cast<size_t>(n));
  for (size_t c = 0; c < parent.size(); ++c) parent[c] = static_cast<int32_t>(c);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    const HalfEdge& e = edges[i];
    if (j - i == 1)
      return edge_name(e.lo, e.hi) + " is used by 1 triangle (a hole): triangle " +
             std::to_string(e.triangle);
    if (j - i > 2) {
      std::string s = edge_name(e.lo, e.hi) + " is used by " + std::to_string(j - i);
      s.append(" triangles: ");
      for (size_t h = i; h < j; ++h) {
        if (h > i) s.append(", ");
        s.append(std::to_string(edges[h].triangle));
      }
      return s;
    }
    const HalfEdge& f = edges[i + 1];
    if (e.forward == f.forward)
      return "triangles " + std::to_string(e.triangle) + " and " + std::to_string(f.triangle) +
             " orient " + edge_name(e.lo, e.hi) + " the same way";
    out.across[3 * e.triangle + e.corner] = f.triangle;
    out.across[3 * f.triangle + f.corner] = e.triangle;
    // e runs a -> b from its corner k; f runs b -> a, so its corner k is b and k + 1 is a.
    const int32_t e_start = 3 * e.triangle + e.corner, e_end = 3 * e.triangle + (e.corner + 1) % 3;
    const int32_t f_start = 3 * f.triangle + f.corner, f_end = 3 * f.triangle + (f.corner + 1) % 3;
    parent[find_root(parent, e_start)] = find_root(parent, f_end);
    parent[find_root(parent, e_end)] = find_root(parent, f_start);
    i = j;
  }

  // A triangle and its reverse pass the edge test: a two-sided sheet, with no inside.
  std::vector<std::array<int32_t, 4>> sorted(static_cast<size_t>(n));
  for (int32_t t = 0; t < n; ++t) {
    std::array<int32_t, 4>& key = sorted[t];
    key = {triangles[t].v[0], triangles[t].v[1], triangles[t].v[2], t};
    std::sort(key.begin(), key.begin() + 3);
  }
  std::sort(sorted.begin(), sorted.end());
  for (int32_t i = 1; i < n; ++i)
    if (std::equal(sorted[i].begin(), sorted[i].begin() + 3, sorted[i - 1].begin()))
      return "triangles " + std::to_string(sorted[i - 1][3]) + " and " +
             std::to_string(sorted[i][3]) + " use the same three vertices (a two-sided sheet)";

  out.corner_begin.assign(static_cast<size_t>(vertex_count) + 1, 0);
  for (const geom::Tri& tri : triangles)
    for (int k = 0; k < 3; ++k) ++out.corner_begin[tri.v[k] + 1];
  for (int32_t v = 0; v < vertex_count; ++v) out.corner_begin[v + 1] += out.corner_begin[v];
  out.corners.resize(3 * static_cast<size_t>(n));
  std::vector<int32_t> fill(out.corner_begin.begin(), out.corner_begin.end() - 1);
  for (int32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) out.corners[fill[triangles[t].v[k]]++] = 3 * t + k;
  for (int32_t v = 0; v < vertex_count; ++v) {
    const int32_t begin = out.corner_begin[v], end = out.corner_begin[v + 1];
    if (begin == end) continue;
    const int32_t root = find_root(parent, out.corners[begin]);
    for (int32_t c = begin + 1; c < end; ++c)
      if (find_root(parent, out.corners[c]) != root) {
        int32_t fans = 0;
        for (int32_t d = begin; d < end; ++d)
          fans += find_root(parent, out.corners[d]) == out.corners[d];
        std::string s = "vertex " + std::to_string(v);
        s.append(" is a pinch point: its triangles form ").append(std::to_string(fans));
        s.append(" separate fans (triangles ").append(std::to_string(out.corners[begin] / 3));
        s.append(" and ")
            .append(std::to_string(out.corners[c] / 3))
            .append(" are in different ones)");
        return s;
      }
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Geometry of one query.

geom::Vec3d unit_or_zero(geom::Vec3d v) {
  const double length = std::sqrt(geom::dot(v, v));
  return length > 0.0 ? (1.0 / length) * v : geom::Vec3d{0.0, 0.0, 0.0};
}

/// p * 2^exponent, exactly (barring underflow to subnormals).
geom::Vec3d scaled(geom::Vec3d p, int exponent) {
  return {std::ldexp(p.x, exponent), std::ldexp(p.y, exponent), std::ldexp(p.z, exponent)};
}

/// The power of two that brings an obstacle's extent into [2^-100, 2^100], where the measure's
/// squares, cross products and volumes cannot overflow or underflow: 0 (no scaling) for every
/// extent already there, so that ordinary scenes are measured as they are.
int scale_exponent_for(double extent) {
  if (!(extent > 0.0) || !std::isfinite(extent) || (extent >= 0x1p-100 && extent <= 0x1p100))
    return 0;
  int exponent = 0;
  std::frexp(extent, &exponent);  // extent = m 2^exponent, m in [0.5, 1)
  return -exponent;
}

/// Features of a triangle: vertex k (corner k), edge k (corner k to k + 1), or the face.
enum Feature : int32_t { kVertex0 = 0, kEdge0 = 3, kFace = 6 };

struct Closest {
  geom::Vec3d point;
  int32_t feature;
};

/// Closest point of segment a -> b (edge `edge` of its triangle) to p.
Closest closest_on_segment(geom::Vec3d p, geom::Vec3d a, geom::Vec3d b, int32_t edge) {
  const geom::Vec3d ab = b - a;
  const double length2 = geom::dot(ab, ab);
  const double t = length2 > 0.0 ? geom::dot(p - a, ab) / length2 : 0.0;
  if (t <= 0.0) return {a, kVertex0 + edge};
  if (t >= 1.0) return {b, kVertex0 + (edge + 1) % 3};
  return {a + t * ab, kEdge0 + edge};
}

/// Closest point of triangle abc to p and its feature: Ericson's Voronoi-region method
/// (Real-Time Collision Detection, 5.1.5), with divisions guarded for zero-length edges and a
/// per-edge fallback when a zero-area triangle reaches the face region.
Closest closest_on_triangle(geom::Vec3d p, geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) {
  const geom::Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = geom::dot(ab, ap), d2 = geom::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, kVertex0 + 0};
  const geom::Vec3d bp = p - b;
  const double d3 = geom::dot(ab, bp), d4 = geom::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, kVertex0 + 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double denom = d1 - d3;
    return {a + (denom > 0.0 ? d1 / denom : 0.0) * ab, kEdge0 + 0};
  }
  const geom::Vec3d cp = p - c;
  const double d5 = geom::dot(ab, cp), d6 = geom::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, kVertex0 + 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double denom = d2 - d6;
    return {a + (denom > 0.0 ? d2 / denom : 0.0) * ac, kEdge0 + 2};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double denom = (d4 - d3) + (d5 - d6);
    return {b + (denom > 0.0 ? (d4 - d3) / denom : 0.0) * (c - b), kEdge0 + 1};
  }
  const double sum = va + vb + vc;
  if (sum > 0.0) {
    const double v = vb / sum, w = vc / sum;
    return {a + v * ab + w * ac, kFace};
  }
  Closest best = closest_on_segment(p, a, b, 0);
  geom::Vec3d d = p - best.point;
  double best2 = geom::dot(d, d);
  for (const Closest& other : {closest_on_segment(p, b, c, 1), closest_on_segment(p, c, a, 2)}) {
    d = p - other.point;
    if (geom::dot(d, d) < best2) best = other, best2 = geom::dot(d, d);
  }
  return best;
}

/// Squared distance from p to a float box, in double: a lower bound on the squared distance
/// to anything in the box (the box is rounded outward), up to the rounding of the few
/// operations here, which can only matter among features whose distances tie within it.
inline double box_distance2(geom::Vec3d p, const geom::Box3f& box) {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double x = geom::coord(p, k);
    const double below = static_cast<double>(box.lo[k]) - x;
    const double above = x - static_cast<double>(box.hi[k]);
    const double gap = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
    sum += gap * gap;
  }
  return sum;
}

/// Everything one query reads, by pointer (the OpenMP loop's shared state).
struct Surface {
  bvh::CompleteTree shape;
  const geom::Box3f* boxes;
  const int32_t* triangle_at;
  const geom::Tri* triangles;
  const geom::Vec3d* positions;
  const int32_t* across;
  const geom::Vec3d* face_normal;
  const geom::Vec3d* vertex_normal;
};

/// A point's distance to the surface, and its depth: the distance when strictly inside, else 0.
struct Reading {
  double distance;  ///< +inf when no triangle was reached (a non-finite point)
  double depth;
};

/// The walk keeps the deferred (farther) children on a fixed stack: one entry per level at
/// most, and the complete tree of at most 2^31 leaves has at most 32 levels.
Reading read_point(geom::Vec3d p, const Surface& s) {
  struct Entry {
    int32_t node;
    double bound;
  };
  Entry stack[64];
  int top = 0;
  const int32_t first_leaf = s.shape.leaf_count - 1;
  double best2 = std::numeric_limits<double>::infinity();
  int32_t best_triangle = -1;
  Closest best{};
  int32_t node = 0;
  double bound = box_distance2(p, s.boxes[0]);
  while (true) {
    if (bound < best2) {
      if (node >= first_leaf) {
        const int32_t t = s.triangle_at[s.shape.position_of(node)];
        const geom::Tri tri = s.triangles[t];
        const Closest c = closest_on_triangle(p, s.positions[tri.v[0]], s.positions[tri.v[1]],
                                              s.positions[tri.v[2]]);
        const geom::Vec3d d = p - c.point;
        const double d2 = geom::dot(d, d);
        if (d2 < best2) best2 = d2, best = c, best_triangle = t;
      } else {
        const int32_t left = 2 * node + 1, right = 2 * node + 2;
        const double left2 = box_distance2(p, s.boxes[left]);
        const double right2 = box_distance2(p, s.boxes[right]);
        const bool left_first = left2 <= right2;
        const int32_t far = left_first ? right : left;
        const double far2 = left_first ? right2 : left2;
        if (far2 < best2) stack[top++] = {far, far2};
        node = left_first ? left : right;
        bound = left_first ? left2 : right2;
        continue;
      }
    }
    if (top == 0) break;
    --top;
    node = stack[top].node;
    bound = stack[top].bound;
  }
  // On the surface: not inside. Not finite: no triangle was reached (a non-finite p).
  if (!(best2 > 0.0 && best2 < std::numeric_limits<double>::infinity()))
    return {std::sqrt(best2), 0.0};
  geom::Vec3d normal;
  if (best.feature == kFace) {
    normal = s.face_normal[best_triangle];
  } else if (best.feature >= kEdge0) {
    const int32_t edge = best.feature - kEdge0;
    normal = s.face_normal[best_triangle] + s.face_normal[s.across[3 * best_triangle + edge]];
  } else {
    normal = s.vertex_normal[s.triangles[best_triangle].v[best.feature - kVertex0]];
  }
  const double distance = std::sqrt(best2);
  return {distance, geom::dot(p - best.point, normal) < 0.0 ? distance : 0.0};
}

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

}  // namespace

std::optional<std::string> why_not_closed(std::span<const geom::Tri> triangles,
                                          int32_t vertex_count) {
  Adjacency unused;
  return analyse(triangles, vertex_count, unused);
}

PenetrationMeter::PenetrationMeter(std::span<const geom::Tri> triangles, int32_t vertex_count)
    : triangles_(triangles.begin(), triangles.end()), vertex_count_(vertex_count) {
  Adjacency adjacency;
  if (const std::optional<std::string> why = analyse(triangles, vertex_count, adjacency))
    throw InternalError("PenetrationMeter: the obstacle is not a closed surface: " + *why);
  across_ = std::move(adjacency.across);
  corner_begin_ = std::move(adjacency.corner_begin);
  corners_ = std::move(adjacency.corners);
}

void PenetrationMeter::update_positions(std::span<const geom::Vec3d> obstacle_positions,
                                        int threads) {
  if (obstacle_positions.size() != static_cast<size_t>(vertex_count_))
    throw InternalError("PenetrationMeter: " + std::to_string(obstacle_positions.size()) +
                        " obstacle positions, expected " + std::to_string(vertex_count_));
  threads = thread_count(threads);
  const auto n = static_cast<int32_t>(triangles_.size());
  if (built_) {
    double moved2 = 0.0;
    bool finite = true;
    for (int32_t v = 0; v < vertex_count_; ++v) {
      const geom::Vec3d d = obstacle_positions[v] - scaled(positions_[v], -scale_exponent_);
      const double d2 = geom::dot(d, d);
      finite &= std::isfinite(d2);
      moved2 = std::max(moved2, d2);
    }
    // A movement that is not finite bounds nothing: the travel is NaN from then on.
    travel_ = finite ? travel_ + std::sqrt(moved2) : std::numeric_limits<double>::quiet_NaN();
  }
  extent_ = 0.0;
  for (const geom::Vec3d& v : obstacle_positions)
    extent_ = std::max({extent_, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  scale_exponent_ = scale_exponent_for(extent_);
  positions_.assign(obstacle_positions.begin(), obstacle_positions.end());
  if (scale_exponent_ != 0)
    for (geom::Vec3d& v : positions_) v = scaled(v, scale_exponent_);
  face_normal_.resize(triangles_.size());
  vertex_normal_.resize(positions_.size());
  const geom::Vec3d* p = positions_.data();
  const geom::Tri* tris = triangles_.data();
  for_each_index(threads, n, 4096, [&](int64_t t) {
    const geom::Tri tri = tris[t];
    face_normal_[t] =
        unit_or_zero(geom::cross(p[tri.v[1]] - p[tri.v[0]], p[tri.v[2]] - p[tri.v[0]]));
  });
  // Gathered per vertex (no scatter, no atomics): the same sums for every thread count.
  for_each_index(threads, vertex_count_, 4096, [&](int64_t v) {
    geom::Vec3d sum{0.0, 0.0, 0.0};
    for (int32_t i = corner_begin_[v]; i < corner_begin_[v + 1]; ++i) {
      const int32_t t = corners_[i] / 3, k = corners_[i] % 3;
      const geom::Tri tri = tris[t];
      const geom::Vec3d e1 = p[tri.v[(k + 1) % 3]] - p[v], e2 = p[tri.v[(k + 2) % 3]] - p[v];
      const geom::Vec3d c = geom::cross(e1, e2);
      const double angle = std::atan2(std::sqrt(geom::dot(c, c)), geom::dot(e1, e2));
      sum = sum + angle * face_normal_[t];
    }
    vertex_normal_[v] = sum;
  });
  // In triangle order on one thread, so that the sum is the same for every thread count.
  double six_volume = 0.0;
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri tri = tris[t];
    six_volume += geom::dot(p[tri.v[0]], geom::cross(p[tri.v[1]], p[tri.v[2]]));
  }
  // Scaled back; where that underflows (an obstacle under ~1e-108), the sign is kept: it says
  // whether the surface is inside out.
  enclosed_volume_ = std::ldexp(six_volume / 6.0, -3 * scale_exponent_);
  if (enclosed_volume_ == 0.0 && six_volume != 0.0)
    enclosed_volume_ = std::copysign(std::numeric_limits<double>::denorm_min(), six_volume);
  const mesh::MeshView mesh = mesh::view_of(positions_, triangles_);
  if (!built_) {
    tree_.build(mesh, threads);
    built_ = true;
  } else {
    tree_.refit(mesh, threads);
  }
}

PenetrationStats PenetrationMeter::measure(std::span<const geom::Vec3d> points, int threads,
                                           std::vector<double>* depths) const {
  return measure_points(points, nullptr, threads, depths);
}

PenetrationStats PenetrationMeter::measure(std::span<const geom::Vec3d> points,
                                           Clearance& clearance, int threads,
                                           std::vector<double>* depths) const {
  return measure_points(points, &clearance, threads, depths);
}

PenetrationStats PenetrationMeter::measure_points(std::span<const geom::Vec3d> points,
                                                  Clearance* clearance, int threads,
                                                  std::vector<double>* depths) const {
  if (!built_) throw InternalError("PenetrationMeter::measure before update_positions");
  std::vector<double> own;
  std::vector<double>& depth = depths ? *depths : own;
  depth.assign(points.size(), 0.0);
  const Surface surface{tree_.shape(),       tree_.boxes().data(), tree_.triangle_at().data(),
                        triangles_.data(),   positions_.data(),    across_.data(),
                        face_normal_.data(), vertex_normal_.data()};
  const auto count = static_cast<int64_t>(points.size());
  const geom::Vec3d* point = points.data();
  double* out = depth.data();
  if (clearance && (clearance->reach.size() != points.size() || clearance->meter != this)) {
    clearance->anchor.assign(points.begin(), points.end());
    clearance->reach.assign(points.size(), -std::numeric_limits<double>::infinity());
    clearance->meter = this;
  }
  geom::Vec3d* anchor = clearance ? clearance->anchor.data() : nullptr;
  double* reach = clearance ? clearance->reach.data() : nullptr;
  const double travel = travel_;
  const int scale_exponent = scale_exponent_;
  int64_t proven_outside = 0;
  // Dynamic chunks: points near the surface cost more than points far from it.
#pragma omp parallel for num_threads(thread_count(threads)) schedule(dynamic, 256) \
    reduction(+ : proven_outside)
  for (int64_t i = 0; i < count; ++i) {
    if (reach) {
      const geom::Vec3d d = point[i] - anchor[i];
      if (std::sqrt(geom::dot(d, d)) + travel < reach[i]) {
        ++proven_outside;
        continue;  // out[i] stays 0
      }
    }
    Reading r = read_point(scaled(point[i], scale_exponent), surface);
    r.distance = std::ldexp(r.distance, -scale_exponent);
    r.depth = std::ldexp(r.depth, -scale_exponent);
    out[i] = r.depth;
    if (reach) {
      // Only an outside point at a positive, finite distance proves anything later. The
      // margin covers the rounding of this distance (relative to it and to the coordinates'
      // magnitude) and of the later movement sums (to the travel's).
      anchor[i] = point[i];
      const double magnitude =
          std::max({std::abs(point[i].x), std::abs(point[i].y), std::abs(point[i].z), extent_}) +
          travel;
      const double margin = 1e-9 * r.distance + 64 * kEpsilon * magnitude;
      reach[i] = r.depth == 0.0 && r.distance > margin && std::isfinite(r.distance + magnitude)
                     ? r.distance - margin + travel
                     : -std::numeric_limits<double>::infinity();
    }
  }

  PenetrationStats stats;
  stats.proven_outside = proven_outside;
  stats.points = count;
  std::vector<double> inside;
  double sum = 0.0;
  for (int64_t i = 0; i < count; ++i)
    if (out[i] > 0.0) {
      inside.push_back(out[i]);
      sum += out[i];
      stats.max_depth = std::max(stats.max_depth, out[i]);
    }
  stats.inside = static_cast<int64_t>(inside.size());
  if (count > 0) stats.ratio = static_cast<double>(stats.inside) / static_cast<double>(count);
  if (!inside.empty()) {
    stats.mean_depth = sum / static_cast<double>(stats.inside);
    // Nearest rank: the ceil(0.95 k)-th smallest, in integers so that 0.95 k is not rounded.
    const int64_t rank = (95 * stats.inside + 99) / 100;
    std::nth_element(inside.begin(), inside.begin() + (rank - 1), inside.end());
    stats.p95_depth = inside[rank - 1];
  }
  return stats;
}

}  // namespace snag::measure
