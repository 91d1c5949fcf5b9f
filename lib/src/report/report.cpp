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
  std::sort(record.pairs.begin(), record.pairs.end(),
            [](const Pair& x, const Pair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  record.degenerate.reserve(result.degenerate.size());
  for (int32_t t : result.degenerate) record.degenerate.push_back({t, polygon_of(t)});
  std::sort(record.degenerate.begin(), record.degenerate.end(),
            [](const Face& x, const Face& y) { return x.face < y.face; });
  record.candidate_pairs = result.candidate_pairs;
  record.filtered_tests = result.filtered_tests;
  record.uncertain_tests = result.uncertain_tests;
  record.confirmed_pairs = result.confirmed_pairs;
  record.rebuilt = result.rebuilt;
  record.tree_quality = result.tree_quality;
  record.times = result.times;
  return record;
}

Summary summarize(const Report& report) {
  Summary s;
  s.frames_checked = static_cast<int64_t>(report.frames.size());
  int64_t worst_crossing = -1;
  int64_t worst_pairs = -1;
  for (size_t i = 0; i < report.frames.size(); ++i) {
    const FrameRecord& f = report.frames[i];
    const int64_t crossing = f.crossing_count();
    const int64_t pairs = static_cast<int64_t>(f.pairs.size());
    s.frames_with_crossings += crossing > 0;
    s.frames_with_pairs += pairs > 0;
    s.pairs += pairs;
    s.crossing += crossing;
    s.touching += pairs - crossing;
    s.degenerate += static_cast<int64_t>(f.degenerate.size());
    s.uncertain_tests += f.uncertain_tests;
    s.confirmed_pairs += f.confirmed_pairs;
    s.topology_changes += f.topology_changed;
    s.check_seconds += f.times.total();
    s.read_seconds += f.read_seconds;
    if (pairs > 0 &&
        (crossing > worst_crossing || (crossing == worst_crossing && pairs > worst_pairs))) {
      s.worst_frame = i;
      worst_crossing = crossing;
      worst_pairs = pairs;
    }
  }
  switch (report.settings.fail_on) {
    case FailOn::crossing:
      s.failed = s.crossing > 0;
      break;
    case FailOn::any:
      s.failed = s.pairs > 0;
      break;
    case FailOn::none:
      s.failed = false;
      break;
  }
  return s;
}

}  // namespace snag::report
