// Exact predicates for integer coordinates (|x| <= 2^20) in 128-bit integer arithmetic: an
// exact provider for the lib tests that needs no CGAL. Throws if a coordinate is not such an
// integer, so a test cannot silently use it on inputs it does not decide exactly.
#pragma once

#include <cmath>
#include <stdexcept>

#include "snag/detect/exact.h"
#include "snag/geom/narrow_phase.h"

namespace snag::test {

struct IntegerPredicates {
  const geom::Vec3d* positions;

  static __int128 integer(double x) {
    if (x != std::floor(x) || std::fabs(x) > 1048576.0)
      throw std::logic_error("IntegerPredicates: not a small integer");
    return static_cast<__int128>(x);
  }
  static geom::Sign sign(__int128 v) {
    return v > 0 ? geom::Sign::positive : (v < 0 ? geom::Sign::negative : geom::Sign::zero);
  }

  geom::Sign orient3d(int32_t a, int32_t b, int32_t c, int32_t d) const {
    const geom::Vec3d pa = positions[a], pb = positions[b], pc = positions[c], pd = positions[d];
    const __int128 ux = integer(pb.x) - integer(pa.x), uy = integer(pb.y) - integer(pa.y),
                   uz = integer(pb.z) - integer(pa.z);
    const __int128 vx = integer(pc.x) - integer(pa.x), vy = integer(pc.y) - integer(pa.y),
                   vz = integer(pc.z) - integer(pa.z);
    const __int128 wx = integer(pd.x) - integer(pa.x), wy = integer(pd.y) - integer(pa.y),
                   wz = integer(pd.z) - integer(pa.z);
    return sign(ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx));
  }
  geom::Sign orient2d(int32_t a, int32_t b, int32_t c, int axis) const {
    double au, av, bu, bv, cu, cv;
    geom::project(positions[a], axis, au, av);
    geom::project(positions[b], axis, bu, bv);
    geom::project(positions[c], axis, cu, cv);
    return sign((integer(bu) - integer(au)) * (integer(cv) - integer(av)) -
                (integer(bv) - integer(av)) * (integer(cu) - integer(au)));
  }
  int dominant_axis(int32_t a, int32_t b, int32_t c) const {
    return geom::dominant_axis(positions[a], positions[b], positions[c]);
  }
  geom::OrientPlane<IntegerPredicates> plane(int32_t a, int32_t b, int32_t c) const {
    return {this, a, b, c};
  }
};

/// Decides uncertain tests with IntegerPredicates (the same decision procedures).
class IntegerResolver final : public detect::ExactResolver {
 public:
  void edge_hits(const detect::ExactContext& context,
                 std::span<const detect::EdgeTriangleTask> tasks, std::span<uint8_t> hit) override {
    const IntegerPredicates pred{context.positions.data()};
    for (size_t i = 0; i < tasks.size(); ++i) {
      const auto [p, q] = context.topology->edges[tasks[i].edge];
      const geom::Tri& t = context.topology->triangles[tasks[i].triangle];
      hit[i] = decide(geom::edge_hits_triangle(pred, p, q, t, side(pred, t, p), side(pred, t, q)));
    }
    edge_calls += tasks.size();
  }
  void pair_kinds(const detect::ExactContext& context, std::span<const detect::FacePair> pairs,
                  std::span<detect::PairKind> kinds) override {
    const IntegerPredicates pred{context.positions.data()};
    for (size_t i = 0; i < pairs.size(); ++i)
      kinds[i] = decide(geom::is_crossing(pred, context.topology->triangles[pairs[i].a],
                                          context.topology->triangles[pairs[i].b]))
                     ? detect::PairKind::crossing
                     : detect::PairKind::touching;
    kind_calls += pairs.size();
  }
  void degenerate(const detect::ExactContext& context, std::span<const int32_t> triangles,
                  std::span<uint8_t> degenerate) override {
    const IntegerPredicates pred{context.positions.data()};
    for (size_t i = 0; i < triangles.size(); ++i) {
      const geom::Tri& t = context.topology->triangles[triangles[i]];
      degenerate[i] = decide(geom::is_degenerate(pred, t.v[0], t.v[1], t.v[2]));
    }
  }
  static geom::Sign side(const IntegerPredicates& pred, const geom::Tri& t, int32_t v) {
    if (v == t.v[0] || v == t.v[1] || v == t.v[2]) return geom::Sign::zero;
    return pred.orient3d(t.v[0], t.v[1], t.v[2], v);
  }
  static bool decide(geom::Answer a) {
    if (a == geom::Answer::uncertain)
      throw std::logic_error("exact provider left a test undecided");
    return a == geom::Answer::yes;
  }
  size_t edge_calls = 0;
  size_t kind_calls = 0;
};

}  // namespace snag::test
