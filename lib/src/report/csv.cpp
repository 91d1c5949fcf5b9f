#include "snag/report/csv.h"

#include <algorithm>
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <numeric>
#include <string_view>
#include <vector>

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
  if (field.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(field);
  std::string quoted = "\"";
  for (char c : field) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

void write_pairs_rows(std::ostream& out, const FrameRecord& f) {
  // std::to_chars into a line buffer: a 100K-pair frame is written in milliseconds, and the
  // bytes do not depend on the stream's locale or flags.
  char line[128];
  char* const after_frame = std::to_chars(line, line + 24, f.frame).ptr;
  *after_frame = ',';
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
    *q++ = '\n';
    out.write(line, q - line);
  };
  const auto by_faces = [](const Pair& x, const Pair& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  };
  // Records are sorted by construction (make_frame_record); only a record built otherwise
  // pays for a sorted copy of pointers, one frame's worth.
  if (std::is_sorted(f.pairs.begin(), f.pairs.end(), by_faces)) {
    for (const Pair& p : f.pairs) write_row(p);
    return;
  }
  std::vector<const Pair*> sorted;
  sorted.reserve(f.pairs.size());
  for (const Pair& p : f.pairs) sorted.push_back(&p);
  std::sort(sorted.begin(), sorted.end(),
            [&](const Pair* x, const Pair* y) { return by_faces(*x, *y); });
  for (const Pair* p : sorted) write_row(*p);
}

void write_frames_row(std::ostream& out, const FrameRecord& f) {
  char numbers[256];
  const int64_t crossing = f.crossing_count();
  const int64_t pairs = static_cast<int64_t>(f.pairs.size());
  out << f.frame << ',' << csv_field(f.file) << ',';
  const int n = std::snprintf(numbers, sizeof numbers,
                              "%d,%" PRId64 ",%" PRId64 ",%" PRId64 ",%zu,%" PRId64 ",%.6f,%d,%d\n",
                              f.triangles, pairs, crossing, pairs - crossing, f.degenerate.size(),
                              f.uncertain_tests, f.times.total(), f.rebuilt ? 1 : 0,
                              f.topology_changed ? 1 : 0);
  out.write(numbers, n);
}

void write_pairs_csv(std::ostream& out, const Report& report) {
  out << pairs_csv_header << '\n';
  for (size_t i : frame_order(report)) write_pairs_rows(out, report.frames[i]);
}

void write_frames_csv(std::ostream& out, const Report& report) {
  out << frames_csv_header << '\n';
  for (size_t i : frame_order(report)) write_frames_row(out, report.frames[i]);
}

}  // namespace snag::report
