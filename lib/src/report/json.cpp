#include "snag/report/json.h"

#include <charconv>
#include <span>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "json_layout.h"
#include "snag/error.h"

namespace snag::report {

namespace {

using nlohmann::ordered_json;

ordered_json seconds_json(const FrameRecord& f) {
  return {
      {"read", f.read_seconds},       {"scan", f.times.scan},         {"build", f.times.build},
      {"refit", f.times.refit},       {"traverse", f.times.traverse}, {"exact", f.times.exact},
      {"classify", f.times.classify}, {"confirm", f.times.confirm},   {"total", f.times.total()}};
}

/// Object `index` of a scene run, for a record's `what` (an InternalError when the record names
/// an object the scene does not have).
const ObjectInput& object_at(std::span<const ObjectInput> objects, int32_t index,
                             const FrameRecord& f, const std::string& what) {
  if (index < 0 || static_cast<size_t>(index) >= objects.size())
    throw InternalError("report: frame " + std::to_string(f.frame) + ": " + what +
                        " names object " + std::to_string(index) + "; the scene has " +
                        std::to_string(objects.size()));
  return objects[index];
}

/// A scene frame's members beyond the single-mesh ones: per object, per check, per
/// penetration measurement, objects by name.
void add_scene_members(ordered_json& j, const FrameRecord& f,
                       std::span<const ObjectInput> objects) {
  if (f.objects.size() != objects.size())
    throw InternalError("report: frame " + std::to_string(f.frame) + " has " +
                        std::to_string(f.objects.size()) + " object records; the scene has " +
                        std::to_string(objects.size()) + " objects");
  ordered_json per_object = ordered_json::array();
  for (size_t i = 0; i < objects.size(); ++i) {
    const ObjectFrame& o = f.objects[i];
    per_object.push_back({{"name", objects[i].name},
                          {"file", o.file},
                          {"moved", o.moved},
                          {"rebuilt", o.rebuilt},
                          {"build_seconds", o.build_seconds},
                          {"refit_seconds", o.refit_seconds},
                          {"tree_quality", o.tree_quality}});
  }
  ordered_json checks = ordered_json::array();
  for (const CheckFrame& c : f.checks)
    checks.push_back({{"objects",
                       {object_at(objects, c.object_a, f, "a check").name,
                        object_at(objects, c.object_b, f, "a check").name}},
                      {"pairs", c.pairs},
                      {"reused", c.reused},
                      {"seconds", c.seconds}});
  ordered_json penetration = ordered_json::array();
  for (const Penetration& p : f.penetration)
    penetration.push_back({{"cloth", object_at(objects, p.cloth, f, "a penetration").name},
                           {"obstacle", object_at(objects, p.obstacle, f, "a penetration").name},
                           {"vertices", p.vertices},
                           {"inside", p.inside},
                           {"ratio", p.ratio},
                           {"max_depth", p.max_depth},
                           {"mean_depth", p.mean_depth},
                           {"p95_depth", p.p95_depth}});
  j["objects"] = std::move(per_object);
  j["checks"] = std::move(checks);
  j["penetration"] = std::move(penetration);
}

/// A frame's record without its pairs (an empty array in their place: json_frame_element
/// writes them, the one part of the report that grows with the pairs).
ordered_json frame_json(const FrameRecord& f, std::span<const ObjectInput> objects, bool baseline) {
  const int64_t crossing = f.crossing_count();
  ordered_json degenerate = ordered_json::array();
  for (const Face& d : f.degenerate) {
    ordered_json face = {{"face", d.face}, {"poly", d.poly}};
    if (!objects.empty())
      face["object"] =
          object_at(objects, d.object, f, "degenerate face " + std::to_string(d.face)).name;
    degenerate.push_back(std::move(face));
  }
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
  if (baseline) j["counts"]["accepted"] = f.accepted_count();
  j["seconds"] = seconds_json(f);
  j["pairs"] = ordered_json::array();
  j["degenerate"] = std::move(degenerate);
  if (!objects.empty()) add_scene_members(j, f, objects);
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
  ordered_json j = {{"frames_checked", s.frames_checked},
                    {"frames_with_crossings", s.frames_with_crossings},
                    {"frames_with_pairs", s.frames_with_pairs},
                    {"worst_frame", std::move(worst)},
                    {"pairs", s.pairs},
                    {"crossing", s.crossing},
                    {"touching", s.touching},
                    {"degenerate", s.degenerate},
                    {"uncertain_tests", s.uncertain_tests},
                    {"confirmed_pairs", s.confirmed_pairs},
                    {"topology_changes", s.topology_changes}};
  if (run.inputs.scene()) {
    j["reused_pairs"] = s.reused_pairs;
    j["max_depth"] = s.max_depth;
  }
  if (run.settings.baseline) {
    j["accepted"] = s.accepted;
    j["accepted_crossing"] = s.accepted_crossing;
    j["new_pairs"] = s.pairs - s.accepted;
    j["new_crossing"] = s.crossing - s.accepted_crossing;
    j["frames_with_new_pairs"] = s.frames_with_new_pairs;
    j["first_new_frame"] = s.first_new_frame ? ordered_json(*s.first_new_frame) : nullptr;
    j["first_failing_frame"] =
        s.first_failing_frame ? ordered_json(*s.first_failing_frame) : nullptr;
  }
  j["builds"] = run.builds;
  j["rebuilds"] = run.rebuilds;
  j["seconds"] = {{"check", s.check_seconds}, {"read", s.read_seconds}, {"wall", run.wall_seconds}};
  j["failed"] = s.failed;
  return j;
}

ordered_json objects_json(std::span<const ObjectInput> objects) {
  const auto optional = [](const auto& value) {
    return value ? ordered_json(*value) : ordered_json(nullptr);
  };
  ordered_json j = ordered_json::array();
  for (const ObjectInput& o : objects)
    j.push_back({{"name", o.name},
                 {"role", o.role},
                 {"sequence", o.sequence},
                 {"group", optional(o.group)},
                 {"still", o.still},
                 {"weld", optional(o.weld)},
                 {"vertices", o.vertices},
                 {"triangles", o.triangles},
                 {"closed", o.closed.empty() ? ordered_json(nullptr) : ordered_json(o.closed)}});
  return j;
}

/// A name as a JSON string value, quotes included, escaped as dump_at escapes it.
std::string json_string(const std::string& text) {
  return ordered_json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::string json_file_element(const std::string& file, bool first) {
  return array_element(ordered_json(file), files_level, first);
}

/// The pairs array of a frame record, laid out as dump(2) lays out an array whose member line
/// is indented `level` times, except that each pair is one line, the object as dump() writes it
/// (no spaces): a pair takes ~60 bytes instead of dump(2)'s ~140 for its seven lines, and a
/// frame's pairs are most of report.json. Written by hand: a frame can have millions of pairs,
/// and building a JSON object per pair cost more than checking the frame.
/// `names`: the scene's object names as JSON strings (json_string), empty for a single mesh.
/// `baseline`: each pair says whether the baseline accepts it. Appended to `out`.
void append_pairs_array(std::string& out, const FrameRecord& f, int level,
                        std::span<const std::string> names, bool baseline) {
  const std::vector<Pair>& pairs = f.pairs;
  const std::string object_margin = indent(level + 1);
  const bool scene = !names.empty();
  // The text between a pair's values, each one piece: a pair is then 5 (single mesh) or 9
  // (scene) copies and 4 numbers, not a dozen small appends.
  const std::string open_first = "\n" + object_margin + "{\"a\":";
  const std::string open_next = "," + open_first;
  const std::string before_b = ",\"b\":";
  const std::string crossing_then_poly = ",\"kind\":\"crossing\",\"poly_a\":";
  const std::string touching_then_poly = ",\"kind\":\"touching\",\"poly_a\":";
  const std::string before_poly_b = ",\"poly_b\":";
  const std::string before_object_a = ",\"object_a\":";
  const std::string before_object_b = ",\"object_b\":";
  const std::string accepted = ",\"accepted\":true";
  const std::string not_accepted = ",\"accepted\":false";
  const std::string close = "}";
  // Written through a cursor into space sized for the longest pair, then trimmed: appending
  // piece by piece spent as long on the string's bookkeeping as on the numbers.
  size_t longest_name = 0;
  for (const std::string& name : names) longest_name = std::max(longest_name, name.size());
  const size_t longest_pair =
      open_next.size() + before_b.size() + crossing_then_poly.size() + before_poly_b.size() +
      close.size() + 4 * 11 +
      (scene ? before_object_a.size() + before_object_b.size() + 2 * (longest_name + 2) : 0) +
      (baseline ? not_accepted.size() : 0);
  const size_t start = out.size();
  out.resize(start + 1 + pairs.size() * longest_pair);
  char* at = out.data() + start;
  *at++ = '[';
  const auto put = [&](std::string_view text) { at = std::copy(text.begin(), text.end(), at); };
  const auto put_number = [&](int32_t value) { at = std::to_chars(at, at + 11, value).ptr; };
  // A scene pair naming no object throws (pair_object_name): `out` is left as it came.
  struct Restore {
    std::string& out;
    size_t size;
    bool done = false;
    ~Restore() {
      if (!done) out.resize(size);
    }
  } restore{out, start};
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Pair& p = pairs[i];
    put(i == 0 ? open_first : open_next);
    put_number(p.a);
    put(before_b);
    put_number(p.b);
    put(p.kind == detect::PairKind::crossing ? crossing_then_poly : touching_then_poly);
    put_number(p.poly_a);
    put(before_poly_b);
    put_number(p.poly_b);
    if (scene) {
      put(before_object_a);
      put(pair_object_name(names, f, p, p.object_a));
      put(before_object_b);
      put(pair_object_name(names, f, p, p.object_b));
    }
    if (baseline) put(p.accepted ? accepted : not_accepted);
    put(close);
  }
  out.resize(static_cast<size_t>(at - out.data()));
  restore.done = true;
  if (!pairs.empty()) {
    out += '\n';
    out += indent(level);
  }
  out += ']';
}

void append_json_frame_element(std::string& out, const FrameRecord& frame, bool first,
                               std::span<const ObjectInput> objects, bool baseline) {
  const std::string text = array_element(frame_json(frame, objects, baseline), frames_level, first);
  if (frame.pairs.empty()) {
    out += text;
    return;
  }
  // The record's members sit two levels inside the frames array's line; its "pairs" member
  // is the only one at that indentation whose value is [] (a string value cannot hold an
  // unescaped quote, so no file or object name can look like it; the scene members' own
  // "pairs" sit deeper and hold numbers).
  const int member_level = frames_level + 2;
  // Built by appending: GCC 12 warns (-Wrestrict, a false positive) on "\n" + std::string
  // once this function inlines more.
  std::string placeholder = "\n";
  placeholder += indent(member_level);
  placeholder += "\"pairs\": []";
  const size_t at = text.find(placeholder);
  if (at == std::string::npos)
    throw InternalError("report.json: no pairs member in a frame record");
  std::vector<std::string> names;
  names.reserve(objects.size());
  for (const ObjectInput& o : objects) names.push_back(json_string(o.name));
  // The record up to its "pairs" member's value, the pairs, then the rest: no copy of the
  // record with the pairs in it.
  const size_t value_at = at + placeholder.size() - 2;
  out.append(text, 0, value_at);
  append_pairs_array(out, frame, member_level, names, baseline);
  out.append(text, value_at + 2);
}

std::string json_frame_element(const FrameRecord& frame, bool first,
                               std::span<const ObjectInput> objects, bool baseline) {
  std::string text;
  append_json_frame_element(text, frame, first, objects, baseline);
  return text;
}

void write_report_json_head(std::ostream& out, const Report& run) {
  const Settings& set = run.settings;
  ordered_json settings = {
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
  if (set.baseline) settings["baseline"] = *set.baseline;
  // The root object (level 0) with its members at level 1, up to the frames array's "[".
  out << "{\n";
  out << member("schema", std::string(json_schema), 1) << ",\n";
  out << member("snag", {{"version", run.snag_version}}, 1) << ",\n";
  out << member("settings", settings, 1) << ",\n";
  out << indent(frames_level) << "\"frames\": [";
}

void write_report_json_tail(std::ostream& out, const Report& run, const Summary& summary,
                            const std::function<void(std::ostream&)>& write_files) {
  const bool no_frames = summary.frames_checked == 0;
  if (!no_frames) out << '\n' << indent(frames_level);
  out << "],\n";
  // inputs is spelled out member by member because its files array is written by the caller.
  out << indent(1) << "\"inputs\": {\n";
  out << member("sequence", run.inputs.sequence, 2) << ",\n";
  out << member("ids", run.inputs.ids, 2) << ",\n";
  out << indent(files_level) << "\"files\": ";
  write_array(out, files_level, no_frames, write_files);
  out << ",\n";
  out << member("coincident_vertices", run.inputs.coincident_vertices, 2) << ",\n";
  out << member("welded_vertices", run.inputs.welded_vertices, 2);
  if (run.inputs.scene()) out << ",\n" << member("objects", objects_json(run.inputs.objects), 2);
  if (run.settings.baseline) {
    const BaselineUse& use = run.inputs.baseline;
    out << ",\n"
        << member("baseline",
                  {{"file", *run.settings.baseline},
                   {"entries", use.entries},
                   {"left_out", use.left_out},
                   {"checked", use.checked},
                   {"unmatched", use.unmatched},
                   {"unmatched_lines", use.unmatched_lines}},
                  2);
  }
  out << "\n";
  out << indent(1) << "},\n";
  out << member("summary", summary_json(run, summary), 1) << "\n";
  out << "}\n";
}

void write_report_json(std::ostream& out, const Report& run, const Summary& summary,
                       const std::function<void(std::ostream&)>& write_files,
                       const std::function<void(std::ostream&)>& write_frames) {
  write_report_json_head(out, run);
  write_frames(out);
  write_report_json_tail(out, run, summary, write_files);
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
          frames << json_frame_element(report.frames[i], i == 0, report.inputs.objects,
                                       report.settings.baseline.has_value());
      });
  return out.str();
}

}  // namespace snag::report
