#include "snag/report/json.h"

#include <nlohmann/json.hpp>

namespace snag::report {

namespace {

using nlohmann::ordered_json;

ordered_json seconds_json(const FrameRecord& f) {
  return {{"read", f.read_seconds},       {"build", f.times.build}, {"refit", f.times.refit},
          {"traverse", f.times.traverse}, {"exact", f.times.exact}, {"classify", f.times.classify},
          {"confirm", f.times.confirm},   {"total", f.times.total()}};
}

ordered_json frame_json(const FrameRecord& f) {
  const int64_t crossing = f.crossing_count();
  ordered_json pairs = ordered_json::array();
  for (const Pair& p : f.pairs)
    pairs.push_back({{"a", p.a},
                     {"b", p.b},
                     {"kind", std::string(detect::to_string(p.kind))},
                     {"poly_a", p.poly_a},
                     {"poly_b", p.poly_b}});
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
  j["pairs"] = std::move(pairs);
  j["degenerate"] = std::move(degenerate);
  return j;
}

}  // namespace

std::string report_json(const Report& report) {
  const Summary s = summarize(report);
  ordered_json j;
  j["schema"] = std::string(json_schema);
  j["snag"] = {{"version", report.snag_version}};

  const Settings& set = report.settings;
  j["settings"] = {{"backend", set.backend},
                   {"backend_requested", set.backend_requested},
                   {"threads", set.threads},
                   {"exact", set.exact},
                   {"exact_predicates", set.exact_predicates},
                   {"weld", set.weld ? ordered_json(*set.weld) : ordered_json(nullptr)},
                   {"rebuild", set.rebuild},
                   {"rebuild_threshold", set.rebuild_threshold},
                   {"fail_on", std::string(to_string(set.fail_on))},
                   {"frames", set.frames ? ordered_json(*set.frames) : ordered_json(nullptr)}};

  ordered_json files = ordered_json::array();
  for (const FrameRecord& f : report.frames) files.push_back(f.file);
  j["inputs"] = {{"sequence", report.inputs.sequence},
                 {"ids", report.inputs.ids},
                 {"files", std::move(files)},
                 {"coincident_vertices", report.inputs.coincident_vertices},
                 {"welded_vertices", report.inputs.welded_vertices}};

  ordered_json frames = ordered_json::array();
  for (const FrameRecord& f : report.frames) frames.push_back(frame_json(f));
  j["frames"] = std::move(frames);

  ordered_json worst = nullptr;
  if (s.worst_frame) {
    const FrameRecord& w = report.frames[*s.worst_frame];
    worst = {{"frame", w.frame},
             {"file", w.file},
             {"crossing", w.crossing_count()},
             {"pairs", w.pairs.size()}};
  }
  j["summary"] = {
      {"frames_checked", s.frames_checked},
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
      {"builds", report.builds},
      {"rebuilds", report.rebuilds},
      {"seconds",
       {{"check", s.check_seconds}, {"read", s.read_seconds}, {"wall", report.wall_seconds}}},
      {"failed", s.failed}};
  // Invalid UTF-8 in a file name is replaced rather than thrown: the report must still be
  // written for a path the filesystem accepted.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace snag::report
