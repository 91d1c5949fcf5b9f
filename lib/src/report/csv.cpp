#include "snag/report/csv.h"

#include <algorithm>
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <numeric>
#include <string_view>
#include <vector>

#include "snag/error.h"

namespace snag::report {

namespace {

/// Frame indices in increasing frame number (stable: the checking order breaks ties), so the
/// rows come out sorted whatever order the frames were recorded in.
std::vector<size_t> frame_order(const Report& report) {
  std::vector<size_t> order(report.frames.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
    return report.frames[x].frame < report.frames[y].frame;
  });
  return order;
}

}  // namespace

std::string csv_field(std::string_view field) {
  // Spaces or tabs at either end are quoted too: a reader that drops those around a value (a
  // --baseline typed by hand) must still get a name such as "cloth " back whole.
  const auto blank = [](char c) { return c == ' ' || c == '\t'; };
  const bool blank_end = !field.empty() && (blank(field.front()) || blank(field.back()));
  if (!blank_end && field.find_first_of(",\"\r\n") == std::string_view::npos)
    return std::string(field);
  std::string quoted = "\"";
  for (char c : field) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

std::string pairs_csv_header_for(std::span<const ObjectInput> objects, bool baseline) {
  std::string header(objects.empty() ? pairs_csv_header : scene_pairs_csv_header);
  if (baseline) header += ",accepted";
  return header;
}

std::string frames_csv_header_for(std::span<const ObjectInput> objects, bool baseline) {
  std::string header(objects.empty() ? frames_csv_header : scene_frames_csv_header);
  if (baseline) header += ",accepted";
  return header;
}

void append_pairs_rows(std::string& out, const FrameRecord& f, std::span<const ObjectInput> objects,
                       bool baseline) {
  // std::to_chars into a line buffer, each line appended to `out`: a 100K-pair frame is
  // written in milliseconds, and the bytes do not depend on a stream's locale or flags.
  char line[128];
  char* const after_frame = std::to_chars(line, line + 24, f.frame).ptr;
  *after_frame = ',';
  // A scene run's rows end in two names of any length: the numbers are copied into `row`,
  // which keeps its capacity from row to row, and the names quoted once per frame.
  std::vector<std::string> names;
  names.reserve(objects.size());
  for (const ObjectInput& o : objects) names.push_back(csv_field(o.name));
  // About 36 bytes a row of a single mesh: one growth of `out` at most, for most frames.
  out.reserve(out.size() + f.pairs.size() * (names.empty() ? 40 : 64));
  const auto write_row = [&](const Pair& p) {
    char* q = after_frame + 1;
    q = std::to_chars(q, q + 12, p.a).ptr;
    *q++ = ',';
    q = std::to_chars(q, q + 12, p.b).ptr;
    const std::string_view kind =
        p.kind == detect::PairKind::crossing ? ",crossing," : ",touching,";
    q = std::copy(kind.begin(), kind.end(), q);
    q = std::to_chars(q, q + 12, p.poly_a).ptr;
    *q++ = ',';
    q = std::to_chars(q, q + 12, p.poly_b).ptr;
    if (names.empty()) {
      if (baseline) q = std::copy_n(p.accepted ? ",1" : ",0", 2, q);
      *q++ = '\n';
      out.append(line, q);
      return;
    }
    out.append(line, q);
    out += ',';
    out += pair_object_name(names, f, p, p.object_a);
    out += ',';
    out += pair_object_name(names, f, p, p.object_b);
    if (baseline) out += p.accepted ? ",1" : ",0";
    out += '\n';
  };
  // Records are sorted by construction (make_frame_record); only a record built otherwise
  // pays for a sorted copy of pointers, one frame's worth.
  if (std::is_sorted(f.pairs.begin(), f.pairs.end(), pair_order)) {
    for (const Pair& p : f.pairs) write_row(p);
    return;
  }
  std::vector<const Pair*> sorted;
  sorted.reserve(f.pairs.size());
  for (const Pair& p : f.pairs) sorted.push_back(&p);
  std::sort(sorted.begin(), sorted.end(),
            [&](const Pair* x, const Pair* y) { return pair_order(*x, *y); });
  for (const Pair* p : sorted) write_row(*p);
}

void write_pairs_rows(std::ostream& out, const FrameRecord& f, std::span<const ObjectInput> objects,
                      bool baseline) {
  std::string rows;
  append_pairs_rows(rows, f, objects, baseline);
  out.write(rows.data(), static_cast<std::streamsize>(rows.size()));
}

void write_frames_row(std::ostream& out, const FrameRecord& f, std::span<const ObjectInput> objects,
                      bool baseline) {
  char numbers[256];
  const int64_t crossing = f.crossing_count();
  const int64_t pairs = static_cast<int64_t>(f.pairs.size());
  out << f.frame << ',' << csv_field(f.file) << ',';
  int n = std::snprintf(
      numbers, sizeof numbers, "%d,%" PRId64 ",%" PRId64 ",%" PRId64 ",%zu,%" PRId64 ",%.6f,%d,%d",
      f.triangles, pairs, crossing, pairs - crossing, f.degenerate.size(), f.uncertain_tests,
      f.times.total(), f.rebuilt ? 1 : 0, f.topology_changed ? 1 : 0);
  out.write(numbers, n);
  if (!objects.empty()) {
    n = std::snprintf(numbers, sizeof numbers, ",%" PRId64 ",%" PRId64 ",%.6f", f.reused_pairs(),
                      f.inside_vertices(), f.max_depth());
    out.write(numbers, n);
  }
  if (baseline) out << ',' << f.accepted_count();
  out << '\n';
}

void write_pairs_csv(std::ostream& out, const Report& report) {
  const bool baseline = report.settings.baseline.has_value();
  out << pairs_csv_header_for(report.inputs.objects, baseline) << '\n';
  for (size_t i : frame_order(report))
    write_pairs_rows(out, report.frames[i], report.inputs.objects, baseline);
}

void write_frames_csv(std::ostream& out, const Report& report) {
  const bool baseline = report.settings.baseline.has_value();
  out << frames_csv_header_for(report.inputs.objects, baseline) << '\n';
  for (size_t i : frame_order(report))
    write_frames_row(out, report.frames[i], report.inputs.objects, baseline);
}

}  // namespace snag::report
