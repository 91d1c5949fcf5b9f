#include "snag/report/report.h"

#include <algorithm>

#include "snag/error.h"

namespace snag::report {

std::string_view to_string(FailOn fail_on) {
  switch (fail_on) {
    case FailOn::crossing:
      return "crossing";
    case FailOn::any:
      return "any";
    case FailOn::none:
      return "none";
  }
  return "crossing";
}

std::optional<FailOn> parse_fail_on(std::string_view text) {
  if (text == "crossing") return FailOn::crossing;
  if (text == "any") return FailOn::any;
  if (text == "none") return FailOn::none;
  return std::nullopt;
}

int64_t FrameRecord::crossing_count() const {
  return std::count_if(pairs.begin(), pairs.end(),
                       [](const Pair& p) { return p.kind == detect::PairKind::crossing; });
}

int64_t FrameRecord::accepted_count() const {
  return std::count_if(pairs.begin(), pairs.end(), [](const Pair& p) { return p.accepted; });
}

int64_t FrameRecord::accepted_crossing_count() const {
  return std::count_if(pairs.begin(), pairs.end(), [](const Pair& p) {
    return p.accepted && p.kind == detect::PairKind::crossing;
  });
}

int64_t FrameRecord::reused_pairs() const {
  int64_t n = 0;
  for (const CheckFrame& c : checks)
    if (c.reused) n += c.pairs;
  return n;
}

int64_t FrameRecord::inside_vertices() const {
  int64_t n = 0;
  for (const Penetration& p : penetration) n += p.inside;
  return n;
}

double FrameRecord::max_depth() const {
  double depth = 0;
  for (const Penetration& p : penetration) depth = std::max(depth, p.max_depth);
  return depth;
}

const std::string& pair_object_name(std::span<const std::string> names, const FrameRecord& f,
                                    const Pair& p, int32_t object) {
  if (object < 0 || static_cast<size_t>(object) >= names.size())
    throw InternalError("report: frame " + std::to_string(f.frame) + ": pair (" +
                        std::to_string(p.a) + ", " + std::to_string(p.b) + ") names object " +
                        std::to_string(object) + "; the scene has " + std::to_string(names.size()));
  return names[object];
}

FrameRecord make_frame_record(int64_t frame, std::string file, const detect::FrameResult& result,
                              std::span<const int32_t> source_polygon, int32_t vertices,
                              int64_t polygons) {
  const auto polygon_of = [&](int32_t triangle) {
    if (triangle < 0 || static_cast<size_t>(triangle) >= source_polygon.size())
      throw InternalError("report: triangle " + std::to_string(triangle) +
                          " has no source polygon (" + std::to_string(source_polygon.size()) +
                          " triangles)");
    return source_polygon[triangle];
  };
  FrameRecord record;
  record.frame = frame;
  record.file = std::move(file);
  record.vertices = vertices;
  record.triangles = static_cast<int32_t>(source_polygon.size());
  record.polygons = polygons;
  record.pairs.reserve(result.pairs.size());
  for (const auto& p : result.pairs) {
    // The checker's contract (a < b, sorted) is what makes the CSV bytes backend independent.
    if (p.a >= p.b)
      throw InternalError("report: pair (" + std::to_string(p.a) + ", " + std::to_string(p.b) +
                          ") is not ordered a < b");
    record.pairs.push_back({p.a, p.b, p.kind, polygon_of(p.a), polygon_of(p.b)});
  }
  // The checker's pairs come sorted (its contract); sorting them again cost more than the rest
  // of the record.
  if (!std::is_sorted(record.pairs.begin(), record.pairs.end(), pair_order))
    std::sort(record.pairs.begin(), record.pairs.end(), pair_order);
  record.degenerate.reserve(result.degenerate.size());
  for (int32_t t : result.degenerate) record.degenerate.push_back({t, polygon_of(t)});
  std::sort(record.degenerate.begin(), record.degenerate.end(), [](const Face& x, const Face& y) {
    return x.object != y.object ? x.object < y.object : x.face < y.face;
  });
  copy_check_counts(result, record);
  return record;
}

void copy_check_counts(const detect::FrameResult& result, FrameRecord& record) {
  record.candidate_pairs = result.candidate_pairs;
  record.filtered_tests = result.filtered_tests;
  record.uncertain_tests = result.uncertain_tests;
  record.confirmed_pairs = result.confirmed_pairs;
  record.rebuilt = result.rebuilt;
  record.tree_quality = result.tree_quality;
  record.times = result.times;
}

void SummaryAccumulator::add(const FrameRecord& frame) {
  Summary& s = summary_;
  const int64_t crossing = frame.crossing_count();
  const int64_t pairs = static_cast<int64_t>(frame.pairs.size());
  const size_t position = static_cast<size_t>(s.frames_checked);
  s.frames_checked += 1;
  s.frames_with_crossings += crossing > 0;
  s.frames_with_pairs += pairs > 0;
  s.pairs += pairs;
  s.crossing += crossing;
  s.touching += pairs - crossing;
  const int64_t accepted = frame.accepted_count();
  s.accepted += accepted;
  s.accepted_crossing += frame.accepted_crossing_count();
  if (accepted < pairs) {
    s.frames_with_new_pairs += 1;
    if (!s.first_new_frame) s.first_new_frame = frame.frame;
  }
  s.degenerate += static_cast<int64_t>(frame.degenerate.size());
  s.uncertain_tests += frame.uncertain_tests;
  s.confirmed_pairs += frame.confirmed_pairs;
  s.topology_changes += frame.topology_changed;
  s.reused_pairs += frame.reused_pairs();
  s.max_depth = std::max(s.max_depth, frame.max_depth());
  s.check_seconds += frame.times.total();
  s.read_seconds += frame.read_seconds;
  // Strictly more crossing, or as many and strictly more pairs: on a full tie the earlier
  // frame stays the worst.
  const bool worse = pairs > 0 && (!s.worst || crossing > s.worst->crossing ||
                                   (crossing == s.worst->crossing && pairs > s.worst->pairs));
  if (worse) {
    s.worst_frame = position;
    s.worst = WorstFrame{frame.frame, frame.file, crossing, pairs};
  }
  const bool frame_fails = std::any_of(frame.pairs.begin(), frame.pairs.end(),
                                       [&](const Pair& p) { return pair_fails(p, fail_on_); });
  if (frame_fails && !s.first_failing_frame) s.first_failing_frame = frame.frame;
  s.failed = s.first_failing_frame.has_value();
}

Summary summarize(const Report& report) {
  SummaryAccumulator accumulator(report.settings.fail_on);
  for (const FrameRecord& frame : report.frames) accumulator.add(frame);
  return accumulator.summary();
}

}  // namespace snag::report
