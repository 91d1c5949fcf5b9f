#include "naive_tri_tri.h"

#include <algorithm>
#include <cmath>

namespace snag::cli::naive {

namespace {

using geom::Vec3d;

/// A point projected on the coordinate plane that drops `axis`.
struct Point2 {
  double u, v;
};

Point2 project(Vec3d p, int axis) {
  return axis == 0 ? Point2{p.y, p.z} : (axis == 1 ? Point2{p.z, p.x} : Point2{p.x, p.y});
}

int largest_axis(Vec3d n) {
  const double x = std::fabs(n.x), y = std::fabs(n.y), z = std::fabs(n.z);
  return x >= y && x >= z ? 0 : (y >= z ? 1 : 2);
}

double orient(Point2 a, Point2 b, Point2 c) {
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

bool within(Point2 a, Point2 b, Point2 p) {  // p on the line ab: inside the segment's box?
  return std::min(a.u, b.u) <= p.u && p.u <= std::max(a.u, b.u) && std::min(a.v, b.v) <= p.v &&
         p.v <= std::max(a.v, b.v);
}

bool segments_meet(Point2 a, Point2 b, Point2 c, Point2 d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
               o4 = orient(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) ||
         (o3 == 0 && within(c, d, a)) || (o4 == 0 && within(c, d, b));
}

bool inside(Point2 p, Point2 a, Point2 b, Point2 c) {
  const double s1 = orient(a, b, p), s2 = orient(b, c, p), s3 = orient(c, a, p);
  const bool negative = s1 < 0 || s2 < 0 || s3 < 0;
  const bool positive = s1 > 0 || s2 > 0 || s3 > 0;
  return !(negative && positive);
}

/// Coplanar triangles (corners f, g) projected along `axis`: an edge crossing or containment.
bool coplanar_meet(const Vec3d f[3], const Vec3d g[3], int axis) {
  Point2 a[3], b[3];
  for (int i = 0; i < 3; ++i) a[i] = project(f[i], axis), b[i] = project(g[i], axis);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_meet(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return true;
  return inside(a[0], b[0], b[1], b[2]) || inside(b[0], a[0], a[1], a[2]);
}

/// Signed distances (scaled by |n|) of the corners p to the plane through q.
void distances(const Vec3d q[3], const Vec3d p[3], Vec3d& normal, double d[3]) {
  normal = cross(q[1] - q[0], q[2] - q[0]);
  const double offset = -dot(normal, q[0]);
  for (int i = 0; i < 3; ++i) d[i] = dot(normal, p[i]) + offset;
}

bool straddles(const double d[3]) {
  return (d[0] > 0 || d[1] > 0 || d[2] > 0) && (d[0] < 0 || d[1] < 0 || d[2] < 0);
}

bool one_side(const double d[3]) {
  return (d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0);
}

/// The interval the triangle (projections p, distances d to the other plane) cuts on the
/// common line, from the corner alone on its side.
void interval(const double p[3], const double d[3], double& t0, double& t1) {
  int k;  // the lone corner
  if (d[0] * d[1] > 0)
    k = 2;
  else if (d[0] * d[2] > 0)
    k = 1;
  else if (d[1] * d[2] > 0 || d[0] != 0)
    k = 0;
  else if (d[1] != 0)
    k = 1;
  else
    k = 2;
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  t0 = p[k] + (p[i] - p[k]) * d[k] / (d[k] - d[i]);
  t1 = p[k] + (p[j] - p[k]) * d[k] / (d[k] - d[j]);
  if (d[k] == d[i]) t0 = p[i];  // both on the plane: the corner itself
  if (d[k] == d[j]) t1 = p[j];
  if (t0 > t1) std::swap(t0, t1);
}

/// Moller's test on the corners f, g.
std::optional<detect::PairKind> triangles_meet(const Vec3d f[3], const Vec3d g[3]) {
  Vec3d ng, nf;
  double df[3], dg[3];
  distances(g, f, ng, df);
  if (one_side(df)) return std::nullopt;
  distances(f, g, nf, dg);
  if (one_side(dg)) return std::nullopt;
  if (df[0] == 0 && df[1] == 0 && df[2] == 0) {
    if (coplanar_meet(f, g, largest_axis(nf))) return detect::PairKind::touching;
    return std::nullopt;
  }
  const int axis = largest_axis(cross(nf, ng));
  double pf[3], pg[3];
  for (int i = 0; i < 3; ++i) pf[i] = geom::coord(f[i], axis), pg[i] = geom::coord(g[i], axis);
  double a0, a1, b0, b1;
  interval(pf, df, a0, a1);
  interval(pg, dg, b0, b1);
  if (a1 < b0 || b1 < a0) return std::nullopt;
  const double overlap = std::min(a1, b1) - std::max(a0, b0);
  return straddles(df) && straddles(dg) && overlap > 0 ? detect::PairKind::crossing
                                                       : detect::PairKind::touching;
}

/// Segment ab against the triangle t.
bool segment_meets(Vec3d a, Vec3d b, const Vec3d t[3]) {
  const Vec3d n = cross(t[1] - t[0], t[2] - t[0]);
  const double da = dot(n, a - t[0]), db = dot(n, b - t[0]);
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return false;
  const int axis = largest_axis(n);
  const Point2 p0 = project(t[0], axis), p1 = project(t[1], axis), p2 = project(t[2], axis);
  if (da == 0 && db == 0) {
    const Point2 pa = project(a, axis), pb = project(b, axis);
    return segments_meet(pa, pb, p0, p1) || segments_meet(pa, pb, p1, p2) ||
           segments_meet(pa, pb, p2, p0) || inside(pa, p0, p1, p2);
  }
  const Vec3d hit = a + (da / (da - db)) * (b - a);
  return inside(project(hit, axis), p0, p1, p2);
}

}  // namespace

std::optional<detect::PairKind> intersect(std::span<const geom::Vec3d> positions,
                                          const geom::Tri& f, const geom::Tri& g) {
  Vec3d pf[3], pg[3];
  for (int i = 0; i < 3; ++i) pf[i] = positions[f.v[i]], pg[i] = positions[g.v[i]];
  int shared = 0, fi = 0, gi = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (f.v[i] == g.v[j]) {
        if (shared == 0) fi = i, gi = j;
        ++shared;
      }
  if (shared == 3) return detect::PairKind::touching;
  if (shared == 2) {
    int f_third = 0, g_third = 0;
    for (int i = 0; i < 3; ++i) {
      if (f.v[i] != g.v[0] && f.v[i] != g.v[1] && f.v[i] != g.v[2]) f_third = i;
      if (g.v[i] != f.v[0] && g.v[i] != f.v[1] && g.v[i] != f.v[2]) g_third = i;
    }
    const Vec3d p = pf[(f_third + 1) % 3], q = pf[(f_third + 2) % 3], r = pf[f_third],
                s = pg[g_third];
    const Vec3d n = cross(q - p, r - p);
    if (dot(n, s - p) != 0) return std::nullopt;
    const int axis = largest_axis(n);
    const Point2 p2 = project(p, axis), q2 = project(q, axis);
    const double side_r = orient(p2, q2, project(r, axis)),
                 side_s = orient(p2, q2, project(s, axis));
    if ((side_r > 0 && side_s > 0) || (side_r < 0 && side_s < 0)) return detect::PairKind::touching;
    return std::nullopt;
  }
  if (shared == 1) {
    const bool meet = segment_meets(pg[(gi + 1) % 3], pg[(gi + 2) % 3], pf) ||
                      segment_meets(pf[(fi + 1) % 3], pf[(fi + 2) % 3], pg);
    if (!meet) return std::nullopt;
    return triangles_meet(pf, pg).value_or(detect::PairKind::touching);
  }
  return triangles_meet(pf, pg);
}

bool degenerate(std::span<const geom::Vec3d> positions, const geom::Tri& t) {
  const Vec3d n =
      cross(positions[t.v[1]] - positions[t.v[0]], positions[t.v[2]] - positions[t.v[0]]);
  return n.x == 0 && n.y == 0 && n.z == 0;
}

}  // namespace snag::cli::naive
