#include "snag/report/json.h"

#include <charconv>
#include <sstream>

#include <nlohmann/json.hpp>

#include "json_layout.h"
#include "snag/error.h"

namespace snag::report {

namespace {

using nlohmann::ordered_json;

ordered_json seconds_json(const FrameRecord& f) {
  return {{"read", f.read_seconds},       {"build", f.times.build},  {"refit", f.times.refit},
          {"traverse", f.times.traverse}, {"exact", f.times.exact},  {"classify", f.times.classify},
          {"confirm", f.times.confirm},   {"total", f.times.total()}};
}

/// A frame's record without its pairs (an empty array in their place: json_frame_element
/// writes them, the one part of the report that grows with the pairs).
ordered_json frame_json(const FrameRecord& f) {
  const int64_t crossing = f.crossing_count();
  ordered_json degenerate = ordered_json::array();
  for (const Face& d : f.degenerate) degenerate.push_back({{"face", d.face}, {"poly", d.poly}});
  ordered_json j;
  j["frame"] = f.frame;
  j["file"] = f.file;
  j["vertices"] = f.vertices;
  j["triangles"] = f.triangles;
  j["polygons"] = f.polygons;
  j["topology_changed"] = f.topology_changed;
  j["rebuilt"] = f.rebuilt;
  j["tree_quality"] = f.tree_quality;
  j["counts"] = {{"pairs", f.pairs.size()},
                 {"crossing", crossing},
                 {"touching", static_cast<int64_t>(f.pairs.size()) - crossing},
                 {"degenerate", f.degenerate.size()},
                 {"candidate_pairs", f.candidate_pairs},
                 {"filtered_tests", f.filtered_tests},
                 {"uncertain_tests", f.uncertain_tests},
                 {"confirmed_pairs", f.confirmed_pairs}};
  j["seconds"] = seconds_json(f);
  j["pairs"] = ordered_json::array();
  j["degenerate"] = std::move(degenerate);
  return j;
}

// Indentation levels of the two arrays that grow with the run: "files" is a member of
// "inputs", a member of the root; "frames" is a member of the root.
constexpr int files_level = 2;
constexpr int frames_level = 1;

std::string indent(int level) {
  return std::string(2 * level, ' ');
}

/// `value` as dump(2) lays it out when it starts on a line indented `level` times: every line
/// after the first indented by 2 * level more spaces. A line break inside a string is
/// escaped by the dump, so every "\n" in it is one the layout put there.
std::string dump_at(const ordered_json& value, int level) {
  // Invalid UTF-8 in a file name is replaced rather than thrown: the report must still be
  // written for a path the filesystem accepted.
  const std::string text = value.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  const std::string margin = indent(level);
  std::string laid_out;
  laid_out.reserve(text.size() + text.size() / 8);
  for (char c : text) {
    laid_out += c;
    if (c == '\n') laid_out += margin;
  }
  return laid_out;
}

/// `"key": value` on a line indented `level` times, without the line's end. `key` is one of
/// the schema's plain names: nothing in it needs escaping.
std::string member(std::string_view key, const ordered_json& value, int level) {
  return indent(level) + '"' + std::string(key) + "\": " + dump_at(value, level);
}

/// An element of an array whose opening line is indented `array_level` times.
std::string array_element(const ordered_json& value, int array_level, bool first) {
  return (first ? "\n" : ",\n") + indent(array_level + 1) + dump_at(value, array_level + 1);
}

/// An array whose elements `write_elements` writes (array_element's text), "[]" when empty.
void write_array(std::ostream& out, int level, bool empty,
                 const std::function<void(std::ostream&)>& write_elements) {
  out << '[';
  write_elements(out);
  if (!empty) out << '\n' << indent(level);
  out << ']';
}

ordered_json summary_json(const Report& run, const Summary& s) {
  ordered_json worst = nullptr;
  if (s.worst)
    worst = {{"frame", s.worst->frame},
             {"file", s.worst->file},
             {"crossing", s.worst->crossing},
             {"pairs", s.worst->pairs}};
  return {{"frames_checked", s.frames_checked},
          {"frames_with_crossings", s.frames_with_crossings},
          {"frames_with_pairs", s.frames_with_pairs},
          {"worst_frame", std::move(worst)},
          {"pairs", s.pairs},
          {"crossing", s.crossing},
          {"touching", s.touching},
          {"degenerate", s.degenerate},
          {"uncertain_tests", s.uncertain_tests},
          {"confirmed_pairs", s.confirmed_pairs},
          {"topology_changes", s.topology_changes},
          {"builds", run.builds},
          {"rebuilds", run.rebuilds},
          {"seconds",
           {{"check", s.check_seconds}, {"read", s.read_seconds}, {"wall", run.wall_seconds}}},
          {"failed", s.failed}};
}

}  // namespace

std::string json_file_element(const std::string& file, bool first) {
  return array_element(ordered_json(file), files_level, first);
}

/// The pairs array of a frame record, laid out as dump(2) lays out the same objects when the
/// array's member line is indented `level` times. Written by hand: a frame can have millions
/// of pairs, and building a JSON object per pair cost more than checking the frame.
std::string pairs_array(const std::vector<Pair>& pairs, int level) {
  const std::string object_margin = indent(level + 1), member_margin = indent(level + 2);
  std::string out = "[";
  out.reserve(pairs.size() * (6 * member_margin.size() + 96));
  char number[16];
  const auto add_member = [&](const char* key, int32_t value, bool last) {
    out += member_margin;
    out += key;
    const auto [end, ec] = std::to_chars(number, number + sizeof number, value);
    out.append(number, end);
    out += last ? "\n" : ",\n";
  };
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Pair& p = pairs[i];
    out += i == 0 ? "\n" : ",\n";
    out += object_margin;
    out += "{\n";
    add_member("\"a\": ", p.a, false);
    add_member("\"b\": ", p.b, false);
    out += member_margin;
    out += p.kind == detect::PairKind::crossing ? "\"kind\": \"crossing\",\n"
                                                : "\"kind\": \"touching\",\n";
    add_member("\"poly_a\": ", p.poly_a, false);
    add_member("\"poly_b\": ", p.poly_b, true);
    out += object_margin;
    out += '}';
  }
  if (!pairs.empty()) {
    out += '\n';
    out += indent(level);
  }
  out += ']';
  return out;
}

std::string json_frame_element(const FrameRecord& frame, bool first) {
  std::string text = array_element(frame_json(frame), frames_level, first);
  if (frame.pairs.empty()) return text;
  // The record's members sit two levels inside the frames array's line; its "pairs" member
  // is the only one at that indentation whose value is [] (a string value cannot hold an
  // unescaped quote, so no file name can look like it).
  const int member_level = frames_level + 2;
  const std::string placeholder = "\n" + indent(member_level) + "\"pairs\": []";
  const size_t at = text.find(placeholder);
  if (at == std::string::npos)
    throw InternalError("report.json: no pairs member in a frame record");
  text.replace(at + placeholder.size() - 2, 2, pairs_array(frame.pairs, member_level));
  return text;
}

void write_report_json(std::ostream& out, const Report& run, const Summary& summary,
                       const std::function<void(std::ostream&)>& write_files,
                       const std::function<void(std::ostream&)>& write_frames) {
  const Settings& set = run.settings;
  const ordered_json settings = {
      {"backend", set.backend},
      {"backend_requested", set.backend_requested},
      {"threads", set.threads},
      {"exact", set.exact},
      {"exact_predicates", set.exact_predicates},
      {"weld", set.weld ? ordered_json(*set.weld) : ordered_json(nullptr)},
      {"rebuild", set.rebuild},
      {"rebuild_threshold", set.rebuild_threshold},
      {"fail_on", std::string(to_string(set.fail_on))},
      {"frames", set.frames ? ordered_json(*set.frames) : ordered_json(nullptr)}};
  const bool no_frames = summary.frames_checked == 0;

  // The root object (level 0) with its members at level 1; inputs is spelled out member by
  // member because its files array is written by the caller.
  out << "{\n";
  out << member("schema", std::string(json_schema), 1) << ",\n";
  out << member("snag", {{"version", run.snag_version}}, 1) << ",\n";
  out << member("settings", settings, 1) << ",\n";
  out << indent(1) << "\"inputs\": {\n";
  out << member("sequence", run.inputs.sequence, 2) << ",\n";
  out << member("ids", run.inputs.ids, 2) << ",\n";
  out << indent(files_level) << "\"files\": ";
  write_array(out, files_level, no_frames, write_files);
  out << ",\n";
  out << member("coincident_vertices", run.inputs.coincident_vertices, 2) << ",\n";
  out << member("welded_vertices", run.inputs.welded_vertices, 2) << "\n";
  out << indent(1) << "},\n";
  out << indent(frames_level) << "\"frames\": ";
  write_array(out, frames_level, no_frames, write_frames);
  out << ",\n";
  out << member("summary", summary_json(run, summary), 1) << "\n";
  out << "}\n";
}

std::string report_json(const Report& report) {
  std::ostringstream out;
  write_report_json(
      out, report, summarize(report),
      [&](std::ostream& files) {
        for (size_t i = 0; i < report.frames.size(); ++i)
          files << json_file_element(report.frames[i].file, i == 0);
      },
      [&](std::ostream& frames) {
        for (size_t i = 0; i < report.frames.size(); ++i)
          frames << json_frame_element(report.frames[i], i == 0);
      });
  return out.str();
}

}  // namespace snag::report
