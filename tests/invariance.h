// The invariance property of issue 4: snag's answer depends only on the input's exact values,
// so it is identical under exact transforms of the input. Shared by the validators tests (CPU
// backend, every thread count, --exact uncertain and all) and the CUDA tests.
//
// What is here:
//  - exact transforms of a mesh: translation by powers of two, scaling by powers of two
//    (uniform or per axis), axis permutations, reflections, cyclic rotation (and reversal) of
//    each face's corners, shuffled face order (with the map back to the original ids) and
//    shuffled vertex ids. Each is an affine bijection of space or a renumbering, which keeps
//    every incidence, every side and every overlap, so the pairs, their kinds and the
//    degenerate faces are the same. Each moves every coordinate without rounding, and says so
//    coordinate by coordinate: an inexact one throws std::logic_error naming the value, so a
//    test can never compare a rounded copy;
//  - a generator of random near-degenerate soups on a binary lattice (so that large
//    translations are exact), with coplanar and collinear clusters, points a few units in the
//    last place off planes, shared vertices and edges, duplicated faces and vertices, and
//    zero-area faces;
//  - the reference answer from CGAL alone (cgal_soup_self_intersections, cgal_pair_kind,
//    CGAL::collinear), and the harness that checks every transform with every method (backend,
//    thread count, --exact mode) and compares the answer, mapped back to original ids, with it;
//  - the hard-case corpus (samples/hard: cases.csv, expected.csv and the OBJ files) with its
//    written answers, welded where a case says so.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "../validators/src/cgal_predicates.h"
#include "hard_corpus.h"
#include "lib/detect_fixture.h"
#include "snag/detect/result.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/weld.h"
#include "snag/validators/cgal_reference.h"
#include "test_paths.h"

namespace snag::test {

// ---- Exact arithmetic on single coordinates ---------------------------------------------------

/// x + t, which must be exact: the rounding error of the sum (Knuth's TwoSum, exact itself) is
/// zero and (x + t) - t gives x back. Throws std::logic_error otherwise.
inline double exact_sum(double x, double t) {
  const double s = x + t;
  const double t_part = s - x;
  const double x_part = s - t_part;
  const double error = (x - x_part) + (t - t_part);
  if (!std::isfinite(s) || error != 0.0 || s - t != x) {
    std::ostringstream what;
    what.precision(17);
    what << "inexact translation: " << x << " + " << t << " rounds to " << s;
    throw std::logic_error(what.str());
  }
  return s;
}

/// x * 2^e, which must be exact: finite, and scaling back gives x (a product by a power of two
/// rounds only where it overflows or loses bits below the subnormal range).
inline double exact_scaled(double x, int e) {
  const double y = std::ldexp(x, e);
  if (!std::isfinite(y) || std::ldexp(y, -e) != x) {
    std::ostringstream what;
    what.precision(17);
    what << "inexact scaling: " << x << " * 2^" << e << " gives " << y;
    throw std::logic_error(what.str());
  }
  return y;
}

inline bool sum_is_exact(double x, double t) {
  const double s = x + t;
  if (!std::isfinite(s)) return false;
  const double t_part = s - x;
  return (x - (s - t_part)) + (t - t_part) == 0.0 && s - t == x;
}

inline double& coordinate(geom::Vec3d& p, int axis) {
  return axis == 0 ? p.x : (axis == 1 ? p.y : p.z);
}

// ---- Transforms -------------------------------------------------------------------------------

/// A transformed mesh and the map back: original_face[i] is the original id of face i.
struct Transformed {
  std::string name;
  SmallMesh mesh;
  std::vector<int32_t> original_face;
};

inline Transformed identity(const SmallMesh& mesh) {
  Transformed t{"identity", mesh, std::vector<int32_t>(mesh.triangles.size())};
  std::iota(t.original_face.begin(), t.original_face.end(), 0);
  return t;
}

inline std::string then(const std::string& before, const std::string& step) {
  return before == "identity" ? step : before + ", " + step;
}

inline std::string power_of_two(double t) {
  if (t == 0) return "0";
  int e = 0;
  std::frexp(t, &e);
  return std::string(t < 0 ? "-" : "") + "2^" + std::to_string(e - 1);
}

/// Translation by t, whose components are 0 or +-2^k; throws if a coordinate would round.
inline Transformed translated(Transformed in, geom::Vec3d t) {
  for (int axis = 0; axis < 3; ++axis) {
    const double c = geom::coord(t, axis);
    int e = 0;
    if (c != 0 && std::fabs(std::frexp(c, &e)) != 0.5)
      throw std::logic_error("translated: " + std::to_string(c) + " is not a power of two");
  }
  for (auto& p : in.mesh.positions)
    p = {exact_sum(p.x, t.x), exact_sum(p.y, t.y), exact_sum(p.z, t.z)};
  in.name = then(in.name, "translate (" + power_of_two(t.x) + ", " + power_of_two(t.y) + ", " +
                              power_of_two(t.z) + ")");
  return in;
}

/// Scaling of each axis by 2^e[axis]; throws if a coordinate would round.
inline Transformed scaled(Transformed in, int ex, int ey, int ez) {
  for (auto& p : in.mesh.positions)
    p = {exact_scaled(p.x, ex), exact_scaled(p.y, ey), exact_scaled(p.z, ez)};
  in.name = then(in.name, "scale (2^" + std::to_string(ex) + ", 2^" + std::to_string(ey) + ", 2^" +
                              std::to_string(ez) + ")");
  return in;
}

/// New axis i is old axis perm[i] (perm a permutation of 0, 1, 2).
inline Transformed permuted_axes(Transformed in, int p0, int p1, int p2) {
  const int perm[3] = {p0, p1, p2};
  if ((1 << p0 | 1 << p1 | 1 << p2) != 7)
    throw std::logic_error("permuted_axes: not a permutation");
  for (auto& p : in.mesh.positions) {
    const geom::Vec3d q = p;
    p = {geom::coord(q, perm[0]), geom::coord(q, perm[1]), geom::coord(q, perm[2])};
  }
  in.name = then(in.name, "axes (" + std::string(1, "xyz"[p0]) + "xyz"[p1] + "xyz"[p2] + ")");
  return in;
}

/// Negates the axes whose bit is set in `mask` (bit 0: x).
inline Transformed reflected(Transformed in, int mask) {
  for (auto& p : in.mesh.positions)
    for (int axis = 0; axis < 3; ++axis)
      if (mask >> axis & 1) coordinate(p, axis) = -coordinate(p, axis);
  std::string axes;
  for (int axis = 0; axis < 3; ++axis)
    if (mask >> axis & 1) axes += "xyz"[axis];
  in.name = then(in.name, "reflect " + axes);
  return in;
}

/// Each face's corners rotated cyclically by 1 or 2 places (chosen per face; orientation kept).
inline Transformed rotated_corners(Transformed in, uint32_t seed) {
  std::mt19937 rng(seed);
  for (auto& t : in.mesh.triangles) {
    const int shift = 1 + static_cast<int>(rng() % 2);
    const geom::Tri old = t;
    for (int k = 0; k < 3; ++k) t.v[k] = old.v[(k + shift) % 3];
  }
  in.name = then(in.name, "rotate corners");
  return in;
}

/// Each face's orientation reversed: (a, b, c) -> (a, c, b).
inline Transformed reversed_corners(Transformed in) {
  for (auto& t : in.mesh.triangles) std::swap(t.v[1], t.v[2]);
  in.name = then(in.name, "reverse corners");
  return in;
}

/// The faces in a random order; original_face follows them.
inline Transformed shuffled_faces(Transformed in, uint32_t seed) {
  std::vector<int32_t> order(in.mesh.triangles.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  std::vector<geom::Tri> triangles;
  std::vector<int32_t> original;
  for (int32_t i : order) {
    triangles.push_back(in.mesh.triangles[i]);
    original.push_back(in.original_face[i]);
  }
  in.mesh.triangles = std::move(triangles);
  in.original_face = std::move(original);
  in.name = then(in.name, "shuffle faces");
  return in;
}

/// The vertices renumbered at random (faces keep their order and corners' positions).
inline Transformed shuffled_vertices(Transformed in, uint32_t seed) {
  const size_t n = in.mesh.positions.size();
  std::vector<int32_t> new_id(n);
  std::iota(new_id.begin(), new_id.end(), 0);
  std::shuffle(new_id.begin(), new_id.end(), std::mt19937(seed));
  std::vector<geom::Vec3d> positions(n);
  for (size_t v = 0; v < n; ++v) positions[new_id[v]] = in.mesh.positions[v];
  for (auto& t : in.mesh.triangles)
    for (int32_t& v : t.v) v = new_id[v];
  in.mesh.positions = std::move(positions);
  in.name = then(in.name, "shuffle vertices");
  return in;
}

/// Translations stop at 2^960, leaving room for the scalings composed with them.
inline constexpr int kMaxTranslationExponent = 960;

/// The exponents k <= kMaxTranslationExponent for which adding `sign` * 2^k to every coordinate
/// on `axis` is exact, in increasing order (usually a short run; empty for coordinates that use
/// their whole mantissa).
inline std::vector<int> exact_translation_exponents(const SmallMesh& mesh, int axis, double sign) {
  std::vector<int> exponents;
  for (int k = -1074; k <= kMaxTranslationExponent; ++k) {
    const double t = sign * std::ldexp(1.0, k);
    bool exact = true;
    for (const auto& p : mesh.positions)
      if (!sum_is_exact(geom::coord(p, axis), t)) {
        exact = false;
        break;
      }
    if (exact) exponents.push_back(k);
  }
  return exponents;
}

/// How far each axis can be scaled exactly: up (largest e with every coordinate times 2^e below
/// 2^1000, which leaves differences finite) and down (largest d with every coordinate times 2^-d
/// exact, into the subnormals).
struct ScaleRange {
  int up[3];
  int down[3];
};

inline ScaleRange exact_scale_range(const SmallMesh& mesh) {
  ScaleRange r{};
  for (int axis = 0; axis < 3; ++axis) {
    int largest = -1100, lowest_bit = 1100;
    for (const auto& p : mesh.positions) {
      const double x = geom::coord(p, axis);
      if (x == 0) continue;
      int e = 0;
      std::frexp(x, &e);  // |x| in [2^(e-1), 2^e)
      largest = std::max(largest, e);
      // The lowest set bit of x: scale its mantissa to an integer and strip trailing zeros.
      double m = std::ldexp(std::fabs(std::frexp(x, &e)), 53);
      int low = e - 53;
      while (std::fmod(m, 2.0) == 0.0) {
        m /= 2;
        ++low;
      }
      lowest_bit = std::min(lowest_bit, low);
    }
    if (largest == -1100) {  // all zero: any scaling is exact
      r.up[axis] = 1000;
      r.down[axis] = 1074;
      continue;
    }
    r.up[axis] = 1000 - largest;
    r.down[axis] = lowest_bit + 1074;
  }
  return r;
}

/// The standard set: every transform on its own, at the magnitudes the mesh allows exactly
/// (the largest and smallest exact translations per axis, the largest exact scalings up and
/// down, uniform and per axis), and two compositions of all of them. Every transform here is
/// exact by construction and checked as applied.
inline std::vector<Transformed> standard_transforms(const SmallMesh& mesh, uint32_t seed) {
  const Transformed id = identity(mesh);
  std::vector<Transformed> out;
  // Translations.
  geom::Vec3d largest{0, 0, 0}, smallest{0, 0, 0}, negative{0, 0, 0};
  for (int axis = 0; axis < 3; ++axis) {
    const double sign = axis == 1 ? -1.0 : 1.0;  // mixed signs across axes
    const std::vector<int> ks = exact_translation_exponents(mesh, axis, sign);
    if (!ks.empty()) {
      coordinate(largest, axis) = sign * std::ldexp(1.0, ks.back());
      coordinate(smallest, axis) = sign * std::ldexp(1.0, ks.front());
    }
    const std::vector<int> down = exact_translation_exponents(mesh, axis, -sign);
    if (!down.empty()) coordinate(negative, axis) = -sign * std::ldexp(1.0, down.back());
  }
  for (const geom::Vec3d& t : {largest, smallest, negative})
    if (!(t == geom::Vec3d{0, 0, 0})) out.push_back(translated(id, t));
  // Scalings.
  const ScaleRange range = exact_scale_range(mesh);
  const int up = std::min({range.up[0], range.up[1], range.up[2]});
  const int down = std::min({range.down[0], range.down[1], range.down[2]});
  // Fixed exponents, clamped to what the mesh allows (a mesh may reach down to 2^-1074).
  auto clamp = [&](int e, int axis) { return std::clamp(e, -range.down[axis], range.up[axis]); };
  out.push_back(scaled(id, clamp(1, 0), clamp(1, 1), clamp(1, 2)));
  out.push_back(scaled(id, clamp(-3, 0), clamp(-3, 1), clamp(-3, 2)));
  if (up > 1) out.push_back(scaled(id, up, up, up));             // the 1e300 range
  if (down > 3) out.push_back(scaled(id, -down, -down, -down));  // subnormal lowest bits
  out.push_back(scaled(id, range.up[0], -range.down[1], 0));     // mixed magnitudes
  out.push_back(scaled(id, -range.down[0] / 2, range.up[1] / 2, -range.down[2]));
  // Axis permutations (an even and an odd one) and reflections.
  out.push_back(permuted_axes(id, 1, 2, 0));
  out.push_back(permuted_axes(id, 0, 2, 1));
  out.push_back(reflected(id, 1));
  out.push_back(reflected(id, 7));
  // Corners and ids.
  out.push_back(rotated_corners(id, seed));
  out.push_back(reversed_corners(id));
  out.push_back(shuffled_faces(id, seed + 1));
  out.push_back(shuffled_vertices(id, seed + 2));
  // Everything at once, in two orders.
  {
    Transformed t =
        shuffled_faces(rotated_corners(shuffled_vertices(id, seed + 3), seed + 4), seed + 5);
    t = reflected(permuted_axes(t, 2, 0, 1), 2);
    if (!(largest == geom::Vec3d{0, 0, 0}))
      // Axes permuted (new x, y, z = old z, x, y), then new y (old x) negated.
      t = translated(t, {largest.z, -largest.x, largest.y});
    const ScaleRange now = exact_scale_range(t.mesh);
    out.push_back(scaled(t, std::clamp(7, -now.down[0], now.up[0]),
                         std::clamp(-5, -now.down[1], now.up[1]),
                         std::clamp(2, -now.down[2], now.up[2])));
  }
  {
    Transformed t = scaled(id, -range.down[0] / 3, range.up[1] / 3, clamp(4, 2));
    t = reversed_corners(shuffled_faces(reflected(t, 5), seed + 6));
    t = permuted_axes(t, 1, 0, 2);
    geom::Vec3d shift{0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
      const std::vector<int> ks = exact_translation_exponents(t.mesh, axis, 1.0);
      if (!ks.empty()) coordinate(shift, axis) = std::ldexp(1.0, ks.back());
    }
    if (!(shift == geom::Vec3d{0, 0, 0})) t = translated(t, shift);
    out.push_back(std::move(t));
  }
  return out;
}

/// How many of the standard transforms are translations (a test on its own generated inputs
/// asserts that some are, so that translation is never silently left out).
inline int translation_count(const std::vector<Transformed>& transforms) {
  int n = 0;
  for (const auto& t : transforms) n += t.name.rfind("translate", 0) == 0;
  return n;
}

// ---- Answers ----------------------------------------------------------------------------------

/// An answer in original face ids: pairs (a < b) sorted by (a, b) with their kinds, degenerate
/// faces sorted.
struct Answer {
  std::vector<detect::FacePair> pairs;
  std::vector<int32_t> degenerate;
  friend bool operator==(const Answer&, const Answer&) = default;
};

/// An answer for a transformed mesh, in the original mesh's face ids.
inline Answer mapped_back(const Answer& in, const Transformed& t) {
  Answer answer;
  for (const auto& p : in.pairs) {
    int32_t a = t.original_face.at(p.a), b = t.original_face.at(p.b);
    if (a > b) std::swap(a, b);
    answer.pairs.push_back({a, b, p.kind});
  }
  std::sort(answer.pairs.begin(), answer.pairs.end(),
            [](const auto& x, const auto& y) { return std::pair(x.a, x.b) < std::pair(y.a, y.b); });
  for (int32_t f : in.degenerate) answer.degenerate.push_back(t.original_face.at(f));
  std::sort(answer.degenerate.begin(), answer.degenerate.end());
  return answer;
}

/// A frame's result for a transformed mesh, in the original mesh's face ids.
inline Answer answer_of(const detect::FrameResult& result, const Transformed& t) {
  return mapped_back(Answer{result.pairs, result.degenerate}, t);
}

/// CGAL's answer, independent of snag's decision procedures: the pairs of
/// cgal_soup_self_intersections (CGAL::do_intersect and CGAL's shared-vertex and shared-edge
/// rules), their kinds from cgal_pair_kind (CGAL's exact intersection construction), and the
/// faces with a repeated corner or collinear corners (CGAL::collinear).
inline Answer cgal_answer(const SmallMesh& mesh) {
  Answer answer;
  for (const auto& [a, b] :
       validators::cgal_soup_self_intersections(mesh.positions, mesh.triangles))
    answer.pairs.push_back(
        {a, b, validators::cgal_pair_kind(mesh.positions, mesh.triangles[a], mesh.triangles[b])});
  auto point = [&](int32_t v) {
    const geom::Vec3d p = mesh.positions[v];
    return validators::Kernel::Point_3(p.x, p.y, p.z);
  };
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const geom::Tri& t = mesh.triangles[f];
    if (t.v[0] == t.v[1] || t.v[1] == t.v[2] || t.v[2] == t.v[0] ||
        CGAL::collinear(point(t.v[0]), point(t.v[1]), point(t.v[2])))
      answer.degenerate.push_back(static_cast<int32_t>(f));
  }
  return answer;
}

inline std::string describe(const detect::FacePair& p) {
  return "(" + std::to_string(p.a) + ", " + std::to_string(p.b) + ", " +
         std::string(detect::to_string(p.kind)) + ")";
}

/// What differs between an expected and a found answer, shortly: counts and the first few
/// pairs and faces on either side only.
inline std::string difference(const Answer& expected, const Answer& found) {
  std::ostringstream out;
  out << expected.pairs.size() << " pairs and " << expected.degenerate.size()
      << " degenerate faces expected, " << found.pairs.size() << " and " << found.degenerate.size()
      << " found";
  auto key = [](const detect::FacePair& p) { return std::tuple(p.a, p.b, p.kind); };
  auto less = [&](const auto& x, const auto& y) { return key(x) < key(y); };
  std::vector<detect::FacePair> missing, extra;
  std::set_difference(expected.pairs.begin(), expected.pairs.end(), found.pairs.begin(),
                      found.pairs.end(), std::back_inserter(missing), less);
  std::set_difference(found.pairs.begin(), found.pairs.end(), expected.pairs.begin(),
                      expected.pairs.end(), std::back_inserter(extra), less);
  auto list = [&](const char* what, const std::vector<detect::FacePair>& pairs) {
    if (pairs.empty()) return;
    out << "; " << what << " (" << pairs.size() << "):";
    for (size_t i = 0; i < pairs.size() && i < 5; ++i) out << " " << describe(pairs[i]);
  };
  list("missing", missing);
  list("extra", extra);
  std::vector<int32_t> dmissing, dextra;
  std::set_difference(expected.degenerate.begin(), expected.degenerate.end(),
                      found.degenerate.begin(), found.degenerate.end(),
                      std::back_inserter(dmissing));
  std::set_difference(found.degenerate.begin(), found.degenerate.end(), expected.degenerate.begin(),
                      expected.degenerate.end(), std::back_inserter(dextra));
  for (const auto& [what, faces] :
       {std::pair{"degenerate missing", &dmissing}, std::pair{"degenerate extra", &dextra}}) {
    if (faces->empty()) continue;
    out << "; " << what << ":";
    for (size_t i = 0; i < faces->size() && i < 5; ++i) out << " " << (*faces)[i];
  }
  return out.str();
}

// ---- The harness ------------------------------------------------------------------------------

/// One way of checking a mesh (a backend, a thread count, an --exact mode), named for messages.
/// Rotated methods (the slow ones) share the transforms: the first transform (by convention
/// the identity) is checked with all of them, each later one with one of them in turn.
struct Method {
  std::string name;
  std::function<detect::FrameResult(const SmallMesh&)> check;
  bool rotated = false;
};

/// Checks every transform with every method (rotated ones in turn) and compares each answer, mapped
/// back to the original ids, with `expected` (CGAL's answer for the untransformed mesh). A
/// difference is a test failure naming `what` (the input and its seed), the method, the transform,
/// what differs, and whether CGAL itself gives the expected answer on the transformed mesh (if not,
/// the transform, not snag, is at fault). Returns the number of comparisons made.
inline int expect_invariant(const std::vector<Transformed>& transforms,
                            const std::vector<Method>& methods, const Answer& expected,
                            const std::string& what) {
  int compared = 0;
  size_t rotated = 0;
  for (const Method& method : methods) rotated += method.rotated;
  size_t turn = 0;
  // Method by method: the CPU backend's OpenMP team keeps its size through a run of checks
  // (alternating team sizes costs milliseconds per check where threads exceed free cores).
  for (const Method& method : methods) {
    const size_t my_turn = method.rotated ? turn++ : 0;
    for (size_t i = 0; i < transforms.size(); ++i) {
      if (method.rotated && i > 0 && (i - 1) % rotated != my_turn) continue;
      const Transformed& t = transforms[i];
      const Answer found = answer_of(method.check(t.mesh), t);
      ++compared;
      if (found == expected) continue;
      const Answer cgal = mapped_back(cgal_answer(t.mesh), t);
      ADD_FAILURE() << what << ", " << method.name << ", transform [" << t.name
                    << "]: " << difference(expected, found)
                    << (cgal == expected ? " (CGAL on the transformed mesh agrees with the "
                                           "original: snag is wrong)"
                                         : " (CGAL on the transformed mesh differs too: "
                                           "the transform is not an invariant)");
      return compared;  // one message per input is enough
    }
  }
  return compared;
}

// ---- Random near-degenerate inputs ------------------------------------------------------------

/// A random soup built for contacts that floating point gets wrong, on a binary lattice:
/// coordinates are integers below 1.25 * 2^bits in magnitude (bits <= 51) times 2^-shift per
/// axis, so translations by 2^k up to 2^(51 - shift) are exact (and checked), and with bits = 51
/// one lattice unit is one or two units in the last place of the largest coordinates.
///  - a few planar clusters: a corner a and lattice directions u, v; points a + s u + t v lie
///    exactly in one plane (s, t small integers), and copies moved 1 to 3 lattice units off it
///    (with bits = 48, a few units in the last place);
///  - collinear runs a + s w and points one unit off them;
///  - random points, and exact duplicates of points under new ids;
/// and faces: coplanar ones in a cluster, ones with one corner a hair off a cluster's plane,
/// ones sharing an edge or a vertex with an earlier face, duplicated faces (same ids, rotated;
/// or the same positions under other ids), zero-area faces (collinear, repeated id), and random
/// ones.
struct NearDegenerateSettings {
  int bits = 48;
  int shift[3] = {0, 0, 0};
  int32_t triangles = 120;
};

/// "seed 7 (bits 48, shifts 0 3 -2)": what a failure message names.
inline std::string describe(uint32_t seed, const NearDegenerateSettings& s) {
  return "seed " + std::to_string(seed) + " (bits " + std::to_string(s.bits) + ", shifts " +
         std::to_string(s.shift[0]) + " " + std::to_string(s.shift[1]) + " " +
         std::to_string(s.shift[2]) + ")";
}

inline SmallMesh near_degenerate_soup(uint32_t seed, const NearDegenerateSettings& s) {
  struct P {
    int64_t x, y, z;
  };
  std::mt19937_64 rng(seed);
  auto uniform = [&](int64_t lo, int64_t hi) {
    return std::uniform_int_distribution<int64_t>(lo, hi)(rng);
  };
  const int64_t R = int64_t{1} << s.bits;
  std::vector<P> points;
  std::vector<std::vector<int32_t>> clusters;  // exactly coplanar point sets
  std::vector<std::vector<int32_t>> near;      // per cluster: points a few units off its plane
  std::vector<std::vector<int32_t>> lines;     // exactly collinear point sets
  auto add = [&](P p) {
    points.push_back(p);
    return static_cast<int32_t>(points.size() - 1);
  };
  auto random_point = [&](int64_t half) {
    return P{uniform(-half, half), uniform(-half, half), uniform(-half, half)};
  };
  auto nudge = [&](P p) {
    const int64_t d = uniform(1, 3) * (uniform(0, 1) ? 1 : -1);
    switch (uniform(0, 2)) {
      case 0:
        p.x += d;
        break;
      case 1:
        p.y += d;
        break;
      default:
        p.z += d;
        break;
    }
    return p;
  };
  for (int c = 0; c < 4; ++c) {
    // |a| <= R/2, |u|, |v| <= R/(8D) and s, t in [-D - 1, 2D + 2] below: |p| <= 1.25 R.
    const int64_t D = int64_t{1} << uniform(0, 3);
    const int64_t reach = std::max<int64_t>(1, R / (8 * D));
    const P a = random_point(R / 2), u = random_point(reach), v = random_point(reach);
    auto at = [&](int64_t si, int64_t ti) {
      return P{a.x + si * u.x + ti * v.x, a.y + si * u.y + ti * v.y, a.z + si * u.z + ti * v.z};
    };
    std::vector<int32_t> cluster{add(a), add(at(D, 0)), add(at(0, D))};
    for (int k = 0; k < 7; ++k) cluster.push_back(add(at(uniform(-D, 2 * D), uniform(-D, 2 * D))));
    std::vector<int32_t> off;
    for (int k = 0; k < 4; ++k)
      off.push_back(add(nudge(points[cluster[uniform(0, cluster.size() - 1)]])));
    clusters.push_back(cluster);
    // A run of collinear points in the cluster's plane, and one a hair off it.
    int64_t du = uniform(-1, 1), dv = uniform(-1, 1);
    if (du == 0 && dv == 0) du = 1;
    const int64_t s0 = uniform(-D, D), t0 = uniform(-D, D);
    std::vector<int32_t> line;
    for (int64_t k = -1; k <= 2; ++k) line.push_back(add(at(s0 + k * du, t0 + k * dv)));
    lines.push_back(line);
    off.push_back(add(nudge(points[line[1]])));
    near.push_back(off);
  }
  for (int k = 0; k < 12; ++k) add(random_point(R));
  // Duplicated positions under new ids.
  const size_t before = points.size();
  for (int k = 0; k < 6; ++k) add(points[uniform(0, before - 1)]);

  for (const P& p : points)
    for (int64_t c : {p.x, p.y, p.z})
      if (c > (int64_t{1} << 52) || c < -(int64_t{1} << 52))
        throw std::logic_error("near_degenerate_soup: bits = " + std::to_string(s.bits) +
                               " leaves no room for exact translations");
  SmallMesh mesh;
  for (const P& p : points)
    mesh.positions.push_back({std::ldexp(static_cast<double>(p.x), -s.shift[0]),
                              std::ldexp(static_cast<double>(p.y), -s.shift[1]),
                              std::ldexp(static_cast<double>(p.z), -s.shift[2])});
  auto pick = [&](const std::vector<int32_t>& set) { return set[uniform(0, set.size() - 1)]; };
  auto any = [&]() { return static_cast<int32_t>(uniform(0, points.size() - 1)); };
  while (static_cast<int32_t>(mesh.triangles.size()) < s.triangles) {
    const size_t c = uniform(0, clusters.size() - 1);
    geom::Tri t{{0, 0, 0}};
    switch (uniform(0, 9)) {
      case 0:
      case 1:  // coplanar in a cluster
        t = {{pick(clusters[c]), pick(clusters[c]), pick(clusters[c])}};
        break;
      case 2:  // a corner a hair off the plane
        t = {{pick(clusters[c]), pick(clusters[c]), pick(near[c])}};
        break;
      case 3:  // through a cluster's plane
        t = {{pick(clusters[c]), any(), any()}};
        break;
      case 4:
      case 5: {  // sharing an edge or a vertex with an earlier face
        if (mesh.triangles.empty()) continue;
        const geom::Tri& f = mesh.triangles[uniform(0, mesh.triangles.size() - 1)];
        const int k = static_cast<int>(uniform(0, 2));
        const int32_t third = uniform(0, 1) ? pick(clusters[c]) : pick(near[c]);
        t = uniform(0, 1) ? geom::Tri{{f.v[(k + 1) % 3], f.v[k], third}}
                          : geom::Tri{{f.v[k], third, pick(clusters[c])}};
        break;
      }
      case 6: {  // a duplicated face: the same ids rotated, or the same positions under new ids
        if (mesh.triangles.empty()) continue;
        const geom::Tri f = mesh.triangles[uniform(0, mesh.triangles.size() - 1)];
        if (uniform(0, 1)) {
          t = {{f.v[1], f.v[2], f.v[0]}};
        } else {
          for (int k = 0; k < 3; ++k) {
            mesh.positions.push_back(mesh.positions[f.v[k]]);
            t.v[k] = static_cast<int32_t>(mesh.positions.size() - 1);
          }
        }
        break;
      }
      case 7: {  // zero area: collinear, or a repeated id
        const int32_t v = pick(clusters[c]);
        t = uniform(0, 3) ? geom::Tri{{pick(lines[c]), pick(lines[c]), pick(lines[c])}}
                          : geom::Tri{{v, pick(clusters[c]), v}};
        break;
      }
      default:  // anything
        t = {{any(), any(), any()}};
        break;
    }
    mesh.triangles.push_back(t);
  }
  return mesh;
}

/// The settings of the random soups the tests use, by seed (0-23 take each combination once):
/// lattices of 51 bits (one unit a unit or two in the last place), 40, 24 and 8 bits, placed in the
/// unit range, at 1, in the 1e-300 and the 1e280 ranges, and with a different magnitude per axis.
inline NearDegenerateSettings near_degenerate_settings(uint32_t seed) {
  static const int kBits[] = {51, 40, 24, 8};
  static const int kShifts[][3] = {{0, 0, 0},          {51, 51, 51},       {20, -30, 45},
                                   {1012, 1012, 1012}, {-920, -920, -920}, {-600, 0, 600}};
  NearDegenerateSettings s;
  s.bits = kBits[seed % 4];
  const auto& shift = kShifts[(seed / 4) % 6];
  for (int k = 0; k < 3; ++k) s.shift[k] = shift[k];
  s.triangles = 30 + static_cast<int32_t>(seed % 3) * 15;
  return s;
}

// ---- The hard-case corpus (samples/hard) ------------------------------------------------------

/// One case of the hard corpus: its mesh as the checker sees it (corners replaced by their
/// weld representatives where the case has a weld) and its written answer.
struct HardCase {
  std::string name;
  SmallMesh mesh;
  Answer expected;
};

/// The cases of samples/hard/cases.csv with their answers from expected.csv; empty when the
/// corpus is absent. Files the table does not list come with CGAL's answer.
inline std::vector<HardCase> hard_cases() {
  std::vector<HardCase> out;
  const auto dir = corpus_dir();
  if (!std::filesystem::is_directory(dir)) return out;
  std::set<std::string> listed;
  for (const CorpusCase& written : load_corpus()) {
    LoadedCase loaded = load(written);
    out.push_back({written.name,
                   {std::move(loaded.mesh.positions), std::move(loaded.triangles)},
                   {written.expected, written.degenerate}});
    listed.insert(written.file);
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".obj" && !listed.count(entry.path().filename().string()))
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    const mesh::Mesh read = io::read_mesh(file);
    HardCase c{
        file.filename().string() + " (not in cases.csv)", {read.positions, read.triangles}, {}};
    c.expected = cgal_answer(c.mesh);
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace snag::test
