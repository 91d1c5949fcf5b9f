// The tests the double-precision filter could not certify, and the interface of whoever
// decides them exactly (validators/: CGAL's exact predicates).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "snag/detect/result.h"
#include "snag/detect/topology.h"
#include "snag/geom/vec3.h"

namespace snag::detect {

/// How signs are decided (`snag check --exact`):
///   off        the double filter decides every sign, even where its error bound says it
///              cannot (those decisions are counted; they may be wrong on degenerate input);
///   uncertain  what the filter cannot certify goes to exact predicates (the default);
///   all        every candidate pair, degeneracy and kind is decided with exact predicates,
///              and every reported pair is confirmed independently (PairConfirmer).
enum class ExactMode : uint8_t { off, uncertain, all };

inline std::string_view to_string(ExactMode mode) {
  return mode == ExactMode::off ? "off" : (mode == ExactMode::uncertain ? "uncertain" : "all");
}
inline std::optional<ExactMode> parse_exact_mode(std::string_view text) {
  for (ExactMode mode : {ExactMode::off, ExactMode::uncertain, ExactMode::all})
    if (text == to_string(mode)) return mode;
  return std::nullopt;
}

/// How the narrow phase decides a candidate pair's edge-triangle tests.
enum class FilterUse : uint8_t {
  certify,    ///< the double filter decides what it can certify; the rest are uncertain
  defer_all,  ///< every test is uncertain, for exact predicates (`--exact all`)
};

/// Does edge `edge` meet triangle `triangle` outside the endpoints the two share by id?
struct EdgeTriangleTask {
  int32_t edge;
  int32_t triangle;
  friend bool operator==(const EdgeTriangleTask&, const EdgeTriangleTask&) = default;
};

/// Everything an exact decision reads: one frame's positions and its topology.
struct ExactContext {
  std::span<const geom::Vec3d> positions;
  const Topology* topology = nullptr;
  /// Threads of the exact stage's parallel loops (CheckSettings::threads); 0: OpenMP's default.
  int threads = 0;
};

class ExactResolver {
 public:
  virtual ~ExactResolver() = default;
  /// hit[i] = 1 when tasks[i]'s edge meets its triangle beyond their shared endpoints.
  virtual void edge_hits(const ExactContext& context, std::span<const EdgeTriangleTask> tasks,
                         std::span<uint8_t> hit) = 0;
  /// kinds[i] = the kind of the intersecting pair pairs[i].
  virtual void pair_kinds(const ExactContext& context, std::span<const FacePair> pairs,
                          std::span<PairKind> kinds) = 0;
  /// degenerate[i] = 1 when triangles[i] has zero area (collinear corners).
  virtual void degenerate(const ExactContext& context, std::span<const int32_t> triangles,
                          std::span<uint8_t> degenerate) = 0;
};

/// A reported pair that an independent check does not confirm.
struct Disagreement {
  FacePair pair;
  std::string what;  ///< e.g. "not intersecting", "crossing, not touching"
};

/// Confirms reported pairs by a method independent of snag's decision procedure (`--exact
/// all`; validators/: CGAL's own triangle intersection tests).
class PairConfirmer {
 public:
  virtual ~PairConfirmer() = default;
  /// The pairs among `pairs` (with their kinds) that the independent check contradicts.
  virtual std::vector<Disagreement> confirm(const ExactContext& context,
                                            std::span<const FacePair> pairs) = 0;
};

}  // namespace snag::detect
