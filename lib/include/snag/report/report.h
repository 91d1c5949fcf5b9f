// What `snag check` reports: the settings and inputs of a run, one record per checked frame
// with its pairs in the ids users see, and a summary. Writers (csv.h, json.h, write.h) turn a
// Report into files, and stream.h writes the same files frame by frame without keeping the
// frames; nothing here depends on how the frames were checked.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "snag/detect/result.h"

namespace snag::report {

/// When a run counts as failed (exit status 1): any crossing pair, any intersecting pair, never.
enum class FailOn { crossing, any, none };

std::string_view to_string(FailOn fail_on);
/// "crossing", "any" or "none"; nullopt otherwise.
std::optional<FailOn> parse_fail_on(std::string_view text);

/// One intersecting pair: triangle ids (the file's, after fan triangulation) and the ids of
/// the file's faces (polygons) they come from. In a scene run each face is also named by its
/// object (an index into Inputs::objects); pairs are ordered (object_a, a) < (object_b, b),
/// and ids are those of each object's own file. A single-mesh run has object 0 throughout.
struct Pair {
  int32_t a = 0;
  int32_t b = 0;
  detect::PairKind kind = detect::PairKind::crossing;
  int32_t poly_a = 0;
  int32_t poly_b = 0;
  int32_t object_a = 0;
  int32_t object_b = 0;
  /// Listed in the run's baseline (--baseline, baseline.h): reported, but it does not fail the
  /// run. Always false without a baseline.
  bool accepted = false;
  friend bool operator==(const Pair&, const Pair&) = default;
};

/// Whether `pair` fails a run under `fail_on` on its own: a crossing pair (with `any`, any
/// pair) that the baseline does not accept.
inline bool pair_fails(const Pair& pair, FailOn fail_on) {
  if (pair.accepted || fail_on == FailOn::none) return false;
  return fail_on == FailOn::any || pair.kind == detect::PairKind::crossing;
}

/// Pair order in every report: by (object_a, a, object_b, b).
inline bool pair_order(const Pair& x, const Pair& y) {
  if (x.object_a != y.object_a) return x.object_a < y.object_a;
  if (x.a != y.a) return x.a < y.a;
  if (x.object_b != y.object_b) return x.object_b < y.object_b;
  return x.b < y.b;
}

/// A zero-area triangle and the file's face it comes from (and its object, in a scene run).
struct Face {
  int32_t face = 0;
  int32_t poly = 0;
  int32_t object = 0;
  friend bool operator==(const Face&, const Face&) = default;
};

/// One object of a scene run in one frame.
struct ObjectFrame {
  std::string file;      ///< the file this frame's positions came from
  bool moved = true;     ///< positions differ from the previous frame's (false: not refit)
  bool rebuilt = false;  ///< its tree was (re)built for this frame
  double build_seconds = 0;
  double refit_seconds = 0;
  double tree_quality = 0;
  int32_t triangles = 0;  ///< this frame's (not written: the reports give the first frame's)
  friend bool operator==(const ObjectFrame&, const ObjectFrame&) = default;
};

/// One check of a scene run (an object against itself, or two objects) in one frame.
struct CheckFrame {
  int32_t object_a = 0;
  int32_t object_b = 0;  ///< == object_a: its self-intersections
  int64_t pairs = 0;
  bool reused = false;  ///< neither object moved: the previous frame's pairs, not checked again
  double seconds = 0;   ///< traversal and narrow phase
  friend bool operator==(const CheckFrame&, const CheckFrame&) = default;
};

/// Cloth vertices inside a closed obstacle in one frame; depths are distances to the
/// obstacle's surface, in the files' units.
struct Penetration {
  int32_t cloth = 0;     ///< object index
  int32_t obstacle = 0;  ///< object index
  int64_t vertices = 0;  ///< the cloth's vertices measured
  int64_t inside = 0;
  double ratio = 0;  ///< inside / vertices
  double max_depth = 0;
  double mean_depth = 0;  ///< over the vertices inside (0 when none)
  double p95_depth = 0;   ///< 95th percentile over the vertices inside, nearest rank
  friend bool operator==(const Penetration&, const Penetration&) = default;
};

struct FrameRecord {
  int64_t frame = 0;  ///< frame number, from the file name (0 for a single file without one)
  std::string file;   ///< path as resolved from the sequence spec
  int32_t vertices = 0;
  int32_t triangles = 0;
  int64_t polygons = 0;          ///< faces as listed in the file
  std::vector<Pair> pairs;       ///< sorted by pair_order, unique
  std::vector<Face> degenerate;  ///< sorted by (object, face)
  int64_t candidate_pairs = 0;
  int64_t filtered_tests = 0;
  /// Tests the double filter did not certify, decided by settings.exact_predicates (with
  /// --exact off: decisions outside the filter's error bound; with all: every test).
  int64_t uncertain_tests = 0;
  int64_t confirmed_pairs = 0;    ///< pairs confirmed independently by CGAL (--exact all)
  bool topology_changed = false;  ///< the face list differs from the previous checked frame's
  bool rebuilt = false;           ///< the tree was built for this frame (always true for the first)
  double tree_quality = 0;
  detect::StageTimes times;  ///< checking only; times.total() is the frame's `seconds`
  double read_seconds = 0;   ///< reading (and welding) the file
  // Scene runs only (empty otherwise): per object, per check, per (cloth, closed obstacle).
  // objects[i] is Inputs::objects[i]: one entry per object of the scene, in that order.
  std::vector<ObjectFrame> objects;
  std::vector<CheckFrame> checks;
  std::vector<Penetration> penetration;
  int64_t reused_pairs() const;     ///< pairs of checks whose objects did not move
  int64_t inside_vertices() const;  ///< sum of penetration[].inside
  double max_depth() const;         ///< largest penetration[].max_depth, 0 when none

  int64_t crossing_count() const;
  int64_t touching_count() const { return static_cast<int64_t>(pairs.size()) - crossing_count(); }
  int64_t accepted_count() const;           ///< pairs the baseline accepts
  int64_t accepted_crossing_count() const;  ///< crossing pairs the baseline accepts
};

/// Copies a checker's counts, rebuild, tree quality and stage times into `record` (what every
/// frame record takes from its result, single mesh or scene).
void copy_check_counts(const detect::FrameResult& result, FrameRecord& record);

/// The entry of `names` (one per scene object, as a writer quotes them) of object `object` of
/// pair `p` in frame `f`; InternalError naming the frame and the pair when the scene has no
/// such object. What the CSV and JSON writers put in a scene pair's object columns.
const std::string& pair_object_name(std::span<const std::string> names, const FrameRecord& f,
                                    const Pair& p, int32_t object);

/// Builds a frame record from a checker's result. `source_polygon[t]` is triangle t's face id
/// in the file (Mesh::source_polygon, one entry per triangle).
FrameRecord make_frame_record(int64_t frame, std::string file, const detect::FrameResult& result,
                              std::span<const int32_t> source_polygon, int32_t vertices,
                              int64_t polygons);

struct Settings {
  std::string backend;            ///< backend that ran ("cpu")
  std::string backend_requested;  ///< as asked on the command line ("auto", "cpu")
  int threads = 0;                ///< the run's threads (--threads resolved), readers included
  std::string exact;              ///< the --exact mode: "off", "uncertain" or "all"
  /// Who decides the tests the filter leaves: "cgal" (exact predicates) or "rounded" (the
  /// signs of the rounded doubles, mode off).
  std::string exact_predicates;
  std::optional<double> weld;    ///< --weld tolerance, if given
  std::string rebuild;           ///< "never", "auto" or "always"
  double rebuild_threshold = 0;  ///< quality factor that triggers a rebuild under "auto"
  FailOn fail_on = FailOn::crossing;
  std::optional<std::string> frames;  ///< --frames selection as given, if any
  /// --baseline file as given, if any: pairs it lists are accepted (Pair::accepted), and the
  /// reports then have their `accepted` columns and members.
  std::optional<std::string> baseline;
};

/// One object of a scene run (Inputs::objects).
struct ObjectInput {
  std::string name;
  std::string role;                  ///< "cloth" or "obstacle"
  std::string sequence;              ///< as resolved (relative to the scene file's directory)
  std::optional<std::string> group;  ///< only this OBJ group of the files
  bool still = false;  ///< one file for every frame: built once, never refit or uploaded again
  std::optional<double> weld;
  int32_t vertices = 0;   ///< first frame
  int32_t triangles = 0;  ///< first frame
  /// Obstacles: "closed" when penetration is measured, else why not (e.g. "edge (3, 7) is
  /// used by 1 triangle (a hole)"); empty for cloth.
  std::string closed;
  friend bool operator==(const ObjectInput&, const ObjectInput&) = default;
};

/// What a run made of its baseline (report.json's inputs.baseline), from Baseline::use().
struct BaselineUse {
  int64_t entries = 0;    ///< distinct pairs the file accepts
  int64_t left_out = 0;   ///< rows marked accepted 0 (new pairs of the run that wrote it)
  int64_t checked = 0;    ///< entries of the frames checked, every-frame entries included
  int64_t unmatched = 0;  ///< of those, entries that accepted no pair
  std::vector<int64_t> unmatched_lines;  ///< their lines in the file (an entry's first), sorted
  friend bool operator==(const BaselineUse&, const BaselineUse&) = default;
};

struct Inputs {
  std::string sequence;      ///< the SEQUENCE argument as given (a scene run: the scene file)
  std::string ids = "file";  ///< "file" (snag's OBJ/PLY readers) or "assimp"
  int64_t coincident_vertices =
      0;  ///< exactly coincident vertices beyond the first of each spot, first frame
  int64_t welded_vertices = 0;  ///< vertices merged into another by --weld, first frame
  /// A scene run's objects (--obstacle, --scene, --split-groups); empty for a single mesh,
  /// whose reports keep the single-mesh columns.
  std::vector<ObjectInput> objects;
  BaselineUse baseline;  ///< written only when Settings::baseline is set
  bool scene() const { return !objects.empty(); }
};

struct Report {
  std::string snag_version;
  Settings settings;
  Inputs inputs;
  std::vector<FrameRecord> frames;  ///< in checking order (increasing frame number)
  int builds = 0;                   ///< tree builds, the first of each topology included
  int rebuilds = 0;                 ///< builds beyond the first of each topology
  double wall_seconds = 0;          ///< the run up to its last frame: reading, checking, rows
};

/// The worst frame's identity and counts, kept by the summary so that nobody needs the frame.
struct WorstFrame {
  int64_t frame = 0;
  std::string file;
  int64_t crossing = 0;
  int64_t pairs = 0;
  int64_t touching() const { return pairs - crossing; }
  friend bool operator==(const WorstFrame&, const WorstFrame&) = default;
};

struct Summary {
  int64_t frames_checked = 0;
  int64_t frames_with_crossings = 0;
  int64_t frames_with_pairs = 0;
  /// Position, in the order the frames were added (for summarize: the index into
  /// Report::frames), of the frame with the most crossing pairs (ties: most pairs, then the
  /// earliest); nullopt when no frame has a pair.
  std::optional<size_t> worst_frame;
  /// That frame's number, file and counts; set exactly when worst_frame is.
  std::optional<WorstFrame> worst;
  int64_t pairs = 0;
  int64_t crossing = 0;
  int64_t touching = 0;
  // With a baseline: the pairs it accepts, and where the first pair it does not is. Without
  // one, accepted and accepted_crossing stay 0, and every pair is new.
  int64_t accepted = 0;
  int64_t accepted_crossing = 0;
  int64_t frames_with_new_pairs = 0;
  std::optional<int64_t> first_new_frame;  ///< number of the first frame added with a new pair
  /// Number of the first frame added that fails the run under fail_on (a new crossing pair, or
  /// with `any` a new pair); nullopt while the run has not failed.
  std::optional<int64_t> first_failing_frame;
  int64_t degenerate = 0;
  int64_t uncertain_tests = 0;
  int64_t confirmed_pairs = 0;
  int64_t topology_changes = 0;
  int64_t reused_pairs = 0;  ///< sum of FrameRecord::reused_pairs() (scene runs; else 0)
  double max_depth = 0;      ///< deepest Penetration::max_depth of any frame (0 when none)
  double check_seconds = 0;  ///< sum of the frames' checking times, in the order added
  double read_seconds = 0;
  /// The run fails under settings.fail_on: a crossing pair (or, with `any`, a pair) that the
  /// baseline does not accept.
  bool failed = false;
  friend bool operator==(const Summary&, const Summary&) = default;
};

/// A run's summary built frame by frame: it holds the counts and the worst frame's number,
/// file and counts, never a frame, so its memory does not grow with the run. summary() is
/// up to date after every add().
class SummaryAccumulator {
 public:
  explicit SummaryAccumulator(FailOn fail_on) : fail_on_(fail_on) {}
  void add(const FrameRecord& frame);
  const Summary& summary() const { return summary_; }

 private:
  FailOn fail_on_;
  Summary summary_;
};

/// The summary of report.frames in their order: a SummaryAccumulator fed every frame.
Summary summarize(const Report& report);

}  // namespace snag::report
