// Axis-aligned boxes in single precision, rounded outward from double coordinates so that a
// box always contains the exact (double) geometry it bounds. 24 bytes per box.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "snag/geom/hd.h"
#include "snag/geom/vec3.h"

namespace snag::geom {

struct Box3f {
  float lo[3];
  float hi[3];
};

#if defined(__CUDA_ARCH__)
/// The largest float not above x (x finite): the conversion rounds down.
SNAG_HD_INLINE float float_down(double x) {
  return __double2float_rd(x);
}
/// The smallest float not below x (x finite): the conversion rounds up.
SNAG_HD_INLINE float float_up(double x) {
  return __double2float_ru(x);
}
#else
/// f moved one unit in the last place away from zero (`away`) or towards it, by its bit pattern.
/// Without branches: whether a conversion rounded the wrong way is a coin toss per coordinate,
/// and the refit's innermost loop mispredicted it. A zero that must step is always -0.0 when
/// the step is down (a negative x converts to -0.0) and +0.0 when it is up, so that its step
/// away from zero, to -+FLT_TRUE_MIN, follows the same rule.
inline float float_step(float f, bool step, bool away) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  bits += static_cast<uint32_t>(step) * (away ? 1u : ~0u);
  std::memcpy(&f, &bits, sizeof bits);
  return f;
}
/// The largest float not above x (x finite): down is away from zero for a negative float.
inline float float_down(double x) {
  const float f = static_cast<float>(x);
  return float_step(f, static_cast<double>(f) > x, std::signbit(f));
}
/// The smallest float not below x (x finite): up is away from zero for a positive float.
inline float float_up(double x) {
  const float f = static_cast<float>(x);
  return float_step(f, static_cast<double>(f) < x, !std::signbit(f));
}
#endif

SNAG_HD_INLINE Box3f empty_box() {
  return {{FLT_MAX, FLT_MAX, FLT_MAX}, {-FLT_MAX, -FLT_MAX, -FLT_MAX}};
}

SNAG_HD_INLINE Box3f triangle_box(Vec3d a, Vec3d b, Vec3d c) {
  Box3f box;
  // Plain comparisons rather than fmin/fmax: coordinates are never NaN (readers reject them),
  // and the library calls would not be inlined.
  for (int k = 0; k < 3; ++k) {
    const double ak = coord(a, k), bk = coord(b, k), ck = coord(c, k);
    const double lo = ak < bk ? (ak < ck ? ak : ck) : (bk < ck ? bk : ck);
    const double hi = ak > bk ? (ak > ck ? ak : ck) : (bk > ck ? bk : ck);
    box.lo[k] = float_down(lo);
    box.hi[k] = float_up(hi);
  }
  return box;
}

SNAG_HD_INLINE Box3f merge(const Box3f& a, const Box3f& b) {
  Box3f m;
  for (int k = 0; k < 3; ++k) {
    m.lo[k] = a.lo[k] < b.lo[k] ? a.lo[k] : b.lo[k];
    m.hi[k] = a.hi[k] > b.hi[k] ? a.hi[k] : b.hi[k];
  }
  return m;
}

/// Closed boxes: touching boxes overlap, because touching triangles intersect. The six
/// comparisons are combined without branches: the traversal's one branch is on the result,
/// and short-circuit branches on each comparison would mispredict far more often.
SNAG_HD_INLINE bool overlap(const Box3f& a, const Box3f& b) {
  return (a.lo[0] <= b.hi[0]) & (b.lo[0] <= a.hi[0]) & (a.lo[1] <= b.hi[1]) & (b.lo[1] <= a.hi[1]) &
         (a.lo[2] <= b.hi[2]) & (b.lo[2] <= a.hi[2]);
}

SNAG_HD_INLINE bool contains(const Box3f& outer, const Box3f& inner) {
  for (int k = 0; k < 3; ++k)
    if (inner.lo[k] < outer.lo[k] || inner.hi[k] > outer.hi[k]) return false;
  return true;
}

/// Half the surface area, 0 for an empty box (whose extents are negative); the tree-quality
/// measure sums it over internal nodes. The extents are clamped by selects, not an early return:
/// nvcc 13.0 compiled the return inside the GPU quality kernel's unrolled loop with the next
/// box's offsets for two of the six loads (cuda/NOTES.md, "A miscompiled early return").
SNAG_HD_INLINE double half_area(const Box3f& b) {
  double extent[3];
  for (int k = 0; k < 3; ++k) {
    const double e = double(b.hi[k]) - b.lo[k];
    extent[k] = e > 0.0 ? e : 0.0;
  }
  return extent[0] * extent[1] + extent[1] * extent[2] + extent[2] * extent[0];
}

}  // namespace snag::geom
