// Small POD vector and box types shared by host and device code.
#pragma once

#include <cstdint>

#include "snag/geom/hd.h"

namespace snag::geom {

/// A point or vector in double precision: the file's coordinates as parsed (24 bytes).
struct Vec3d {
  double x, y, z;
};

SNAG_HD_INLINE Vec3d operator-(Vec3d a, Vec3d b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
SNAG_HD_INLINE Vec3d operator+(Vec3d a, Vec3d b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
SNAG_HD_INLINE Vec3d operator*(double s, Vec3d a) {
  return {s * a.x, s * a.y, s * a.z};
}
SNAG_HD_INLINE double dot(Vec3d a, Vec3d b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
SNAG_HD_INLINE Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
SNAG_HD_INLINE double coord(Vec3d a, int axis) {
  return axis == 0 ? a.x : (axis == 1 ? a.y : a.z);
}
SNAG_HD_INLINE bool operator==(Vec3d a, Vec3d b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

/// A triangle's three corner indices into a position array.
struct Tri {
  int32_t v[3];
};

}  // namespace snag::geom
