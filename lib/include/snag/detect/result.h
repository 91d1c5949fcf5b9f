// What checking one frame produces: the intersecting triangle pairs with their kinds, the
// degenerate faces, and what it took to decide them.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace snag::detect {

/// `crossing`: not coplanar, each triangle has corners strictly on both sides of the other's
/// plane, and they share a segment of positive length. `touching`: every other intersecting pair.
enum class PairKind : uint8_t { crossing = 0, touching = 1 };

inline std::string_view to_string(PairKind kind) {
  return kind == PairKind::crossing ? "crossing" : "touching";
}

/// An intersecting pair of triangle ids, a < b.
struct FacePair {
  int32_t a;
  int32_t b;
  PairKind kind;
  friend bool operator==(const FacePair&, const FacePair&) = default;
};

/// Seconds spent per stage of one frame (reading excluded).
struct StageTimes {
  double build = 0;  ///< tree (re)build, when one happened this frame
  double refit = 0;
  double traverse = 0;  ///< traversal with the filtered narrow phase
  double exact = 0;     ///< uncertain tests decided with exact predicates
  double classify = 0;  ///< sorting, deduplication and crossing/touching
  double confirm = 0;   ///< independent confirmation of the reported pairs (`--exact all`)
  /// The degenerate-triangle scan. A backend may queue the refit, the tree quality and the
  /// traversal ahead of their calls and start them with it (the GPU's does): its wait then
  /// covers their start, and their own stages only what was left.
  double scan = 0;
  double total() const { return scan + build + refit + traverse + exact + classify + confirm; }
  StageTimes& operator+=(const StageTimes& other) {
    build += other.build;
    refit += other.refit;
    traverse += other.traverse;
    exact += other.exact;
    classify += other.classify;
    confirm += other.confirm;
    scan += other.scan;
    return *this;
  }
};

/// One part (a scene's object) in one frame.
struct PartOutcome {
  bool moved = true;     ///< its positions differ from the previous frame's (or it is new)
  bool rebuilt = false;  ///< its tree was (re)built this frame
  double build_seconds = 0;
  double refit_seconds = 0;  ///< 0 when it did not move: nothing to refit
  double tree_quality = 0;
};

/// One check of a scene (a part against itself or two parts) in one frame.
struct CheckOutcome {
  int32_t part_a = 0;
  int32_t part_b = 0;
  int64_t pairs = 0;
  /// Neither part moved: the pairs are the previous frame's, taken without checking.
  bool reused = false;
  double seconds = 0;  ///< traversal and narrow phase (exact decisions are in times.exact)
};

struct FrameResult {
  std::vector<FacePair> pairs;      ///< sorted by (a, b), no duplicates
  std::vector<int32_t> degenerate;  ///< zero-area triangles, sorted; left out of the search
  int64_t candidate_pairs = 0;      ///< pairs whose boxes overlap
  int64_t filtered_tests = 0;       ///< orientation-based tests decided by the double filter
  /// Tests the filter did not certify, decided by the exact stage (with `--exact off`, by the
  /// rounded doubles: decisions outside the filter's error bound; with `all`, every test).
  int64_t uncertain_tests = 0;
  int64_t confirmed_pairs = 0;  ///< pairs confirmed independently (`--exact all`)
  bool rebuilt = false;         ///< a tree was (re)built for this frame
  double tree_quality = 0;  ///< the first part's: sum of internal-node half areas over the root's
  StageTimes times;
  std::vector<PartOutcome> parts;    ///< per part of the topology (one for a single mesh)
  std::vector<CheckOutcome> checks;  ///< per check of the topology, in its order

  int64_t crossing_count() const {
    int64_t n = 0;
    for (const auto& p : pairs) n += p.kind == PairKind::crossing;
    return n;
  }
  int64_t touching_count() const { return static_cast<int64_t>(pairs.size()) - crossing_count(); }
};

}  // namespace snag::detect
