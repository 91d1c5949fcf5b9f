// Report writers: exact CSV bytes for a hand-built run, report.json read back field by field,
// and files written completely or not at all.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "report_files.h"
#include "snag/error.h"
#include "snag/report/csv.h"
#include "snag/report/json.h"
#include "snag/report/report.h"
#include "snag/report/write.h"

namespace snag::report {
namespace {

namespace fs = std::filesystem;
using detect::PairKind;

/// Two frames recorded out of frame order (frame 12 first), one with an unsorted pair list
/// from a hypothetical backend, a file name that needs quoting, and a quad split into triangles
/// 2 and 3 (polygon 2).
Report hand_built_report() {
  Report r;
  r.snag_version = "9.9.9";
  r.settings.backend = "cpu";
  r.settings.backend_requested = "auto";
  r.settings.threads = 2;
  r.settings.exact = "cgal";
  r.settings.weld = 0.001;
  r.settings.rebuild = "auto";
  r.settings.rebuild_threshold = 1.5;
  r.settings.fail_on = FailOn::crossing;
  r.settings.frames = "10-12";
  r.inputs.sequence = "shots/dress.%04d.obj";
  r.inputs.coincident_vertices = 4;
  r.inputs.welded_vertices = 3;

  const std::vector<int32_t> polygons = {0, 1, 2, 2, 3};  // triangles 2 and 3 are one quad

  detect::FrameResult f12;
  f12.pairs = {{0, 4, PairKind::touching}};
  f12.degenerate = {1};
  f12.candidate_pairs = 9;
  f12.filtered_tests = 30;
  f12.uncertain_tests = 2;
  f12.rebuilt = true;
  f12.tree_quality = 2.5;
  f12.times = {0.001, 0.0, 0.0025, 0.0005, 0.00025};
  FrameRecord r12 = make_frame_record(12, "shots/dress,\"v2\".0012.obj", f12, polygons, 8, 4);
  r12.topology_changed = true;
  r12.read_seconds = 0.01;

  detect::FrameResult f10;
  f10.pairs = {{1, 3, PairKind::crossing}, {0, 2, PairKind::crossing}, {0, 3, PairKind::touching}};
  f10.candidate_pairs = 5;
  f10.filtered_tests = 20;
  f10.tree_quality = 2.0;
  f10.rebuilt = true;
  f10.times = {0.002, 0.0, 0.001, 0.0, 0.0};
  f10.times.scan = 0.0005;
  FrameRecord r10 = make_frame_record(10, "shots/dress.0010.obj", f10, polygons, 8, 4);
  r10.read_seconds = 0.02;

  detect::FrameResult f11;  // clean
  f11.times = {0.0, 0.0001, 0.0002, 0.0, 0.0};
  FrameRecord r11 = make_frame_record(11, "shots/dress.0011.obj", f11, polygons, 8, 4);

  r.frames = {std::move(r12), std::move(r10), std::move(r11)};
  r.builds = 2;
  r.rebuilds = 0;
  r.wall_seconds = 0.5;
  return r;
}

TEST(ReportRecord, CarriesPolygonIdsAndSortsPairs) {
  const Report r = hand_built_report();
  const FrameRecord& f10 = r.frames[1];
  ASSERT_EQ(f10.pairs.size(), 3u);
  EXPECT_EQ(f10.pairs[0], (Pair{0, 2, PairKind::crossing, 0, 2}));
  EXPECT_EQ(f10.pairs[1], (Pair{0, 3, PairKind::touching, 0, 2}));
  EXPECT_EQ(f10.pairs[2], (Pair{1, 3, PairKind::crossing, 1, 2}));
  EXPECT_EQ(f10.crossing_count(), 2);
  EXPECT_EQ(f10.touching_count(), 1);
  EXPECT_EQ(f10.triangles, 5);
  EXPECT_EQ(r.frames[0].degenerate, (std::vector<Face>{{1, 1}}));
}

TEST(ReportRecord, RejectsUnorderedPairAndUnknownTriangle) {
  const std::vector<int32_t> polygons = {0, 1, 2};
  detect::FrameResult bad;
  bad.pairs = {{2, 1, PairKind::crossing}};
  EXPECT_THROW(make_frame_record(1, "f.obj", bad, polygons, 3, 3), InternalError);
  bad.pairs = {{1, 7, PairKind::crossing}};
  EXPECT_THROW(make_frame_record(1, "f.obj", bad, polygons, 3, 3), InternalError);
}

TEST(ReportSummary, CountsWorstFrameAndVerdict) {
  Report r = hand_built_report();
  Summary s = summarize(r);
  EXPECT_EQ(s.frames_checked, 3);
  EXPECT_EQ(s.frames_with_crossings, 1);
  EXPECT_EQ(s.frames_with_pairs, 2);
  ASSERT_TRUE(s.worst_frame.has_value());
  EXPECT_EQ(r.frames[*s.worst_frame].frame, 10);
  EXPECT_EQ(s.pairs, 4);
  EXPECT_EQ(s.crossing, 2);
  EXPECT_EQ(s.touching, 2);
  EXPECT_EQ(s.degenerate, 1);
  EXPECT_EQ(s.uncertain_tests, 2);
  EXPECT_EQ(s.topology_changes, 1);
  EXPECT_DOUBLE_EQ(s.read_seconds, 0.03);
  EXPECT_TRUE(s.failed);

  // Frame 12 has only a touching pair: it fails under `any`, not under `crossing`.
  r.frames.erase(r.frames.begin() + 1);
  s = summarize(r);
  EXPECT_EQ(r.frames[*s.worst_frame].frame, 12);
  EXPECT_FALSE(s.failed);
  r.settings.fail_on = FailOn::any;
  EXPECT_TRUE(summarize(r).failed);
  r.settings.fail_on = FailOn::none;
  EXPECT_FALSE(summarize(r).failed);

  r.frames.clear();
  s = summarize(r);
  EXPECT_FALSE(s.worst_frame.has_value());
  EXPECT_FALSE(s.failed);
}

TEST(ReportFailOn, ParsesItsThreeValues) {
  for (FailOn f : {FailOn::crossing, FailOn::any, FailOn::none})
    EXPECT_EQ(parse_fail_on(to_string(f)), f);
  EXPECT_FALSE(parse_fail_on("all").has_value());
  EXPECT_FALSE(parse_fail_on("").has_value());
}

TEST(ReportCsv, PairsBytes) {
  std::ostringstream out;
  write_pairs_csv(out, hand_built_report());
  EXPECT_EQ(out.str(),
            "frame,face_a,face_b,kind,poly_a,poly_b\n"
            "10,0,2,crossing,0,2\n"
            "10,0,3,touching,0,2\n"
            "10,1,3,crossing,1,2\n"
            "12,0,4,touching,0,3\n");
}

TEST(ReportCsv, FramesBytes) {
  std::ostringstream out;
  write_frames_csv(out, hand_built_report());
  EXPECT_EQ(out.str(),
            "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,rebuilt,"
            "topology_changed\n"
            "10,shots/dress.0010.obj,5,3,2,1,0,0,0.003500,1,0\n"
            "11,shots/dress.0011.obj,5,0,0,0,0,0,0.000300,0,0\n"
            "12,\"shots/dress,\"\"v2\"\".0012.obj\",5,1,0,1,1,2,0.004250,1,1\n");
}

TEST(ReportCsv, EmptyRunHasHeadersOnly) {
  Report r;
  std::ostringstream pairs, frames;
  write_pairs_csv(pairs, r);
  write_frames_csv(frames, r);
  EXPECT_EQ(pairs.str(), std::string(pairs_csv_header) + "\n");
  EXPECT_EQ(frames.str(), std::string(frames_csv_header) + "\n");
}

TEST(ReportCsv, QuotesOnlyWhenNeeded) {
  EXPECT_EQ(csv_field("plain/path.obj"), "plain/path.obj");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("line\nbreak"), "\"line\nbreak\"");
  // Blanks at either end are quoted, so that a reader dropping those around values (a
  // --baseline) keeps them; inside a field they need nothing.
  EXPECT_EQ(csv_field("cloth "), "\"cloth \"");
  EXPECT_EQ(csv_field("\tbody"), "\"\tbody\"");
  EXPECT_EQ(csv_field("left sleeve"), "left sleeve");
}

TEST(ReportJson, ParsesBackWithTheFields) {
  const auto j = nlohmann::json::parse(report_json(hand_built_report()));
  EXPECT_EQ(j.at("schema"), "snag-report/2");
  EXPECT_EQ(j.at("snag").at("version"), "9.9.9");

  const auto& set = j.at("settings");
  EXPECT_EQ(set.at("backend"), "cpu");
  EXPECT_EQ(set.at("backend_requested"), "auto");
  EXPECT_EQ(set.at("threads"), 2);
  EXPECT_EQ(set.at("exact"), "cgal");
  EXPECT_DOUBLE_EQ(set.at("weld").get<double>(), 0.001);
  EXPECT_EQ(set.at("rebuild"), "auto");
  EXPECT_DOUBLE_EQ(set.at("rebuild_threshold").get<double>(), 1.5);
  EXPECT_EQ(set.at("fail_on"), "crossing");
  EXPECT_EQ(set.at("frames"), "10-12");

  const auto& in = j.at("inputs");
  EXPECT_EQ(in.at("sequence"), "shots/dress.%04d.obj");
  EXPECT_EQ(in.at("ids"), "file");
  EXPECT_EQ(in.at("files").size(), 3u);
  EXPECT_EQ(in.at("coincident_vertices"), 4);
  EXPECT_EQ(in.at("welded_vertices"), 3);

  const auto& frames = j.at("frames");
  ASSERT_EQ(frames.size(), 3u);
  const auto& f10 = frames.at(1);
  EXPECT_EQ(f10.at("frame"), 10);
  EXPECT_EQ(f10.at("file"), "shots/dress.0010.obj");
  EXPECT_EQ(f10.at("vertices"), 8);
  EXPECT_EQ(f10.at("triangles"), 5);
  EXPECT_EQ(f10.at("polygons"), 4);
  EXPECT_EQ(f10.at("topology_changed"), false);
  EXPECT_EQ(f10.at("rebuilt"), true);
  EXPECT_DOUBLE_EQ(f10.at("tree_quality").get<double>(), 2.0);
  EXPECT_EQ(f10.at("counts").at("pairs"), 3);
  EXPECT_EQ(f10.at("counts").at("crossing"), 2);
  EXPECT_EQ(f10.at("counts").at("touching"), 1);
  EXPECT_EQ(f10.at("counts").at("degenerate"), 0);
  EXPECT_EQ(f10.at("counts").at("candidate_pairs"), 5);
  EXPECT_EQ(f10.at("counts").at("filtered_tests"), 20);
  EXPECT_EQ(f10.at("counts").at("uncertain_tests"), 0);
  EXPECT_DOUBLE_EQ(f10.at("seconds").at("read").get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(f10.at("seconds").at("build").get<double>(), 0.002);
  EXPECT_DOUBLE_EQ(f10.at("seconds").at("traverse").get<double>(), 0.001);
  EXPECT_DOUBLE_EQ(f10.at("seconds").at("scan").get<double>(), 0.0005);
  EXPECT_DOUBLE_EQ(f10.at("seconds").at("total").get<double>(), 0.0035);
  ASSERT_EQ(f10.at("pairs").size(), 3u);
  EXPECT_EQ(
      f10.at("pairs").at(2),
      (nlohmann::json{{"a", 1}, {"b", 3}, {"kind", "crossing"}, {"poly_a", 1}, {"poly_b", 2}}));
  EXPECT_TRUE(f10.at("degenerate").empty());

  const auto& f12 = frames.at(0);
  EXPECT_EQ(f12.at("file"), "shots/dress,\"v2\".0012.obj");
  EXPECT_EQ(f12.at("topology_changed"), true);
  EXPECT_EQ(f12.at("degenerate"), (nlohmann::json::array({{{"face", 1}, {"poly", 1}}})));
  EXPECT_EQ(f12.at("counts").at("uncertain_tests"), 2);

  const auto& s = j.at("summary");
  EXPECT_EQ(s.at("frames_checked"), 3);
  EXPECT_EQ(s.at("frames_with_crossings"), 1);
  EXPECT_EQ(s.at("frames_with_pairs"), 2);
  EXPECT_EQ(s.at("worst_frame").at("frame"), 10);
  EXPECT_EQ(s.at("worst_frame").at("file"), "shots/dress.0010.obj");
  EXPECT_EQ(s.at("worst_frame").at("crossing"), 2);
  EXPECT_EQ(s.at("worst_frame").at("pairs"), 3);
  EXPECT_EQ(s.at("pairs"), 4);
  EXPECT_EQ(s.at("crossing"), 2);
  EXPECT_EQ(s.at("touching"), 2);
  EXPECT_EQ(s.at("degenerate"), 1);
  EXPECT_EQ(s.at("uncertain_tests"), 2);
  EXPECT_EQ(s.at("topology_changes"), 1);
  EXPECT_EQ(s.at("builds"), 2);
  EXPECT_EQ(s.at("rebuilds"), 0);
  EXPECT_NEAR(s.at("seconds").at("check").get<double>(), 0.00805, 1e-12);
  EXPECT_DOUBLE_EQ(s.at("seconds").at("wall").get<double>(), 0.5);
  EXPECT_EQ(s.at("failed"), true);
}

TEST(ReportJson, NullsForAbsentSettingsAndWorstFrame) {
  Report r;
  r.settings.fail_on = FailOn::none;
  const auto j = nlohmann::json::parse(report_json(r));
  EXPECT_TRUE(j.at("settings").at("weld").is_null());
  EXPECT_TRUE(j.at("settings").at("frames").is_null());
  EXPECT_TRUE(j.at("summary").at("worst_frame").is_null());
  EXPECT_TRUE(j.at("frames").empty());
  EXPECT_EQ(j.at("summary").at("failed"), false);
}

/// A scene run of three objects: a cloth, a body whose name needs CSV quoting (closed, so its
/// penetration is measured) and a still floor with a hole. Frame 7 has a self pair of the
/// dress, pairs against both obstacles (listed out of pair_order, one with face_a > face_b
/// across objects), a degenerate face of the body and a reused check; frame 8 is clean and
/// has no penetration entry. Every time and depth is a sum of powers of two.
Report scene_report() {
  Report r;
  r.snag_version = "9.9.9";
  r.settings.backend = "cpu";
  r.settings.backend_requested = "cpu";
  r.settings.threads = 2;
  r.settings.exact = "uncertain";
  r.settings.exact_predicates = "cgal";
  r.settings.rebuild = "auto";
  r.settings.rebuild_threshold = 1.5;
  r.inputs.sequence = "shots/scene.json";
  ObjectInput dress{"dress", "cloth", "shots/dress.%04d.obj", std::nullopt, false, 1e-6, 8, 5, ""};
  ObjectInput body{
      "body, left", "obstacle", "shots/body.%04d.obj", "torso", false, std::nullopt, 6, 8,
      "closed"};
  ObjectInput floor{"floor", "obstacle", "floor.obj", std::nullopt, true, std::nullopt, 4, 2, ""};
  floor.closed = "edge (0, 1) is used by 1 triangle (a hole)";
  r.inputs.objects = {dress, body, floor};

  FrameRecord f7;
  f7.frame = 7;
  f7.file = "shots/dress.0007.obj";
  f7.vertices = 18;
  f7.triangles = 15;
  f7.polygons = 14;
  f7.pairs = {{2, 5, PairKind::crossing, 2, 5, 0, 1},
              {0, 3, PairKind::touching, 0, 2, 0, 0},
              {4, 1, PairKind::touching, 3, 1, 0, 1},
              {0, 1, PairKind::crossing, 0, 0, 0, 2}};
  f7.degenerate = {{1, 1, 1}};
  f7.candidate_pairs = 11;
  f7.filtered_tests = 20;
  f7.rebuilt = true;
  f7.tree_quality = 2.5;
  f7.times.build = 0.5;
  f7.times.traverse = 0.25;
  f7.times.classify = 0.125;
  f7.read_seconds = 0.0625;
  f7.objects = {{"shots/dress.0007.obj", true, true, 0.5, 0, 2.5},
                {"shots/body.0007.obj", true, false, 0, 0.25, 1.5},
                {"floor.obj", false, false, 0, 0, 1.0}};
  f7.checks = {{0, 0, 1, false, 0.125}, {0, 1, 2, false, 0.25}, {0, 2, 1, true, 0}};
  f7.penetration = {{0, 1, 8, 3, 0.375, 0.015625, 0.0078125, 0.015625}};

  FrameRecord f8;
  f8.frame = 8;
  f8.file = "shots/dress.0008.obj";
  f8.vertices = 18;
  f8.triangles = 15;
  f8.polygons = 14;
  f8.candidate_pairs = 4;
  f8.filtered_tests = 4;
  f8.tree_quality = 2.5;
  f8.times.refit = 0.25;
  f8.times.traverse = 0.125;
  f8.objects = {{"shots/dress.0008.obj", true, false, 0, 0.25, 2.5},
                {"shots/body.0007.obj", false, false, 0, 0, 1.5},
                {"floor.obj", false, false, 0, 0, 1.0}};
  f8.checks = {{0, 0, 0, false, 0.0625}, {0, 1, 0, true, 0}, {0, 2, 0, true, 0}};

  r.frames = {std::move(f7), std::move(f8)};
  r.builds = 3;
  r.wall_seconds = 1.5;
  return r;
}

TEST(ReportScene, FrameTotalsAndSummary) {
  const Report r = scene_report();
  const FrameRecord& f7 = r.frames[0];
  EXPECT_EQ(f7.reused_pairs(), 1);
  EXPECT_EQ(f7.inside_vertices(), 3);
  EXPECT_DOUBLE_EQ(f7.max_depth(), 0.015625);
  EXPECT_EQ(r.frames[1].reused_pairs(), 0);
  EXPECT_EQ(r.frames[1].inside_vertices(), 0);
  EXPECT_EQ(r.frames[1].max_depth(), 0.0);
  const Summary s = summarize(r);
  EXPECT_EQ(s.pairs, 4);
  EXPECT_EQ(s.crossing, 2);
  EXPECT_EQ(s.reused_pairs, 1);
  EXPECT_DOUBLE_EQ(s.max_depth, 0.015625);
  // A single-mesh run has neither.
  const Summary single = summarize(hand_built_report());
  EXPECT_EQ(single.reused_pairs, 0);
  EXPECT_EQ(single.max_depth, 0.0);
}

TEST(ReportScene, PairsCsvBytes) {
  std::ostringstream out;
  write_pairs_csv(out, scene_report());
  EXPECT_EQ(out.str(),
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "7,0,3,touching,0,2,dress,dress\n"
            "7,0,1,crossing,0,0,dress,floor\n"
            "7,2,5,crossing,2,5,dress,\"body, left\"\n"
            "7,4,1,touching,3,1,dress,\"body, left\"\n");
}

TEST(ReportScene, FramesCsvBytes) {
  std::ostringstream out;
  write_frames_csv(out, scene_report());
  EXPECT_EQ(out.str(),
            "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,seconds,rebuilt,"
            "topology_changed,reused_pairs,inside_vertices,max_depth\n"
            "7,shots/dress.0007.obj,15,4,2,2,1,0,0.875000,1,0,1,3,0.015625\n"
            "8,shots/dress.0008.obj,15,0,0,0,0,0,0.375000,0,0,0,0,0.000000\n");
}

TEST(ReportScene, RowWritersTakeTheObjectsAndLeaveThemOutWithout) {
  const Report r = scene_report();
  const FrameRecord& f7 = r.frames[0];
  std::ostringstream scene_pairs, scene_frame, single_pairs, single_frame;
  write_pairs_rows(scene_pairs, f7, r.inputs.objects);
  write_frames_row(scene_frame, f7, r.inputs.objects);
  write_pairs_rows(single_pairs, f7);
  write_frames_row(single_frame, f7);
  EXPECT_EQ(scene_pairs.str().substr(0, 31), "7,0,3,touching,0,2,dress,dress\n");
  EXPECT_EQ(scene_frame.str(), "7,shots/dress.0007.obj,15,4,2,2,1,0,0.875000,1,0,1,3,0.015625\n");
  // Without objects: today's columns (the rows in pair_order all the same).
  EXPECT_EQ(single_pairs.str(),
            "7,0,3,touching,0,2\n"
            "7,0,1,crossing,0,0\n"
            "7,2,5,crossing,2,5\n"
            "7,4,1,touching,3,1\n");
  EXPECT_EQ(single_frame.str(), "7,shots/dress.0007.obj,15,4,2,2,1,0,0.875000,1,0\n");
  EXPECT_EQ(pairs_csv_header_for(r.inputs.objects), scene_pairs_csv_header);
  EXPECT_EQ(frames_csv_header_for({}), frames_csv_header);
}

TEST(ReportScene, JsonParsesBackWithTheSceneKeys) {
  const std::string text = report_json(scene_report());
  EXPECT_EQ(report_json_layout(text), text);  // dump(2)'s layout, a pair to a line
  const auto j = nlohmann::json::parse(text);
  EXPECT_EQ(j.at("schema"), "snag-report/2");

  const auto& objects = j.at("inputs").at("objects");
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_EQ(objects.at(0), (nlohmann::json{{"name", "dress"},
                                           {"role", "cloth"},
                                           {"sequence", "shots/dress.%04d.obj"},
                                           {"group", nullptr},
                                           {"still", false},
                                           {"weld", 1e-6},
                                           {"vertices", 8},
                                           {"triangles", 5},
                                           {"closed", nullptr}}));
  EXPECT_EQ(objects.at(1).at("name"), "body, left");
  EXPECT_EQ(objects.at(1).at("role"), "obstacle");
  EXPECT_EQ(objects.at(1).at("group"), "torso");
  EXPECT_TRUE(objects.at(1).at("weld").is_null());
  EXPECT_EQ(objects.at(1).at("closed"), "closed");
  EXPECT_EQ(objects.at(2).at("still"), true);
  EXPECT_EQ(objects.at(2).at("vertices"), 4);
  EXPECT_EQ(objects.at(2).at("triangles"), 2);
  EXPECT_EQ(objects.at(2).at("closed"), "edge (0, 1) is used by 1 triangle (a hole)");

  const auto& f7 = j.at("frames").at(0);
  EXPECT_EQ(f7.at("frame"), 7);
  const auto& pairs = f7.at("pairs");
  ASSERT_EQ(pairs.size(), 4u);  // the record's order, as for a single mesh
  EXPECT_EQ(pairs.at(0), (nlohmann::json{{"a", 2},
                                         {"b", 5},
                                         {"kind", "crossing"},
                                         {"poly_a", 2},
                                         {"poly_b", 5},
                                         {"object_a", "dress"},
                                         {"object_b", "body, left"}}));
  EXPECT_EQ(pairs.at(1).at("object_b"), "dress");
  EXPECT_EQ(pairs.at(3).at("object_b"), "floor");
  EXPECT_EQ(f7.at("degenerate"),
            (nlohmann::json::array({{{"face", 1}, {"poly", 1}, {"object", "body, left"}}})));

  const auto& per_object = f7.at("objects");
  ASSERT_EQ(per_object.size(), 3u);
  EXPECT_EQ(per_object.at(1), (nlohmann::json{{"name", "body, left"},
                                              {"file", "shots/body.0007.obj"},
                                              {"moved", true},
                                              {"rebuilt", false},
                                              {"build_seconds", 0.0},
                                              {"refit_seconds", 0.25},
                                              {"tree_quality", 1.5}}));
  EXPECT_EQ(per_object.at(0).at("rebuilt"), true);
  EXPECT_EQ(per_object.at(0).at("build_seconds"), 0.5);
  EXPECT_EQ(per_object.at(2).at("name"), "floor");
  EXPECT_EQ(per_object.at(2).at("moved"), false);

  const auto& checks = f7.at("checks");
  ASSERT_EQ(checks.size(), 3u);
  EXPECT_EQ(
      checks.at(0),
      (nlohmann::json{
          {"objects", {"dress", "dress"}}, {"pairs", 1}, {"reused", false}, {"seconds", 0.125}}));
  EXPECT_EQ(checks.at(1).at("objects"), (nlohmann::json{"dress", "body, left"}));
  EXPECT_EQ(checks.at(1).at("pairs"), 2);
  EXPECT_EQ(checks.at(2).at("objects"), (nlohmann::json{"dress", "floor"}));
  EXPECT_EQ(checks.at(2).at("reused"), true);

  EXPECT_EQ(f7.at("penetration"), (nlohmann::json::array({{{"cloth", "dress"},
                                                           {"obstacle", "body, left"},
                                                           {"vertices", 8},
                                                           {"inside", 3},
                                                           {"ratio", 0.375},
                                                           {"max_depth", 0.015625},
                                                           {"mean_depth", 0.0078125},
                                                           {"p95_depth", 0.015625}}})));
  const auto& f8 = j.at("frames").at(1);
  EXPECT_TRUE(f8.at("pairs").empty());
  EXPECT_TRUE(f8.at("penetration").empty());
  EXPECT_EQ(f8.at("objects").size(), 3u);

  const auto& s = j.at("summary");
  EXPECT_EQ(s.at("reused_pairs"), 1);
  EXPECT_EQ(s.at("max_depth"), 0.015625);
  EXPECT_EQ(s.at("pairs"), 4);
  EXPECT_EQ(s.at("builds"), 3);
}

TEST(ReportScene, SingleMeshJsonHasNoSceneKeys) {
  const auto j = nlohmann::json::parse(report_json(hand_built_report()));
  EXPECT_FALSE(j.at("inputs").contains("objects"));
  for (const auto& frame : j.at("frames")) {
    for (const char* key : {"objects", "checks", "penetration"})
      EXPECT_FALSE(frame.contains(key)) << key;
    for (const auto& pair : frame.at("pairs")) EXPECT_FALSE(pair.contains("object_a"));
    for (const auto& face : frame.at("degenerate")) EXPECT_FALSE(face.contains("object"));
  }
  EXPECT_FALSE(j.at("summary").contains("reused_pairs"));
  EXPECT_FALSE(j.at("summary").contains("max_depth"));
}

TEST(ReportScene, UnknownObjectsAreInternalErrors) {
  const Report good = scene_report();
  const auto all_writers_throw = [](const Report& r) {
    EXPECT_THROW(report_json(r), InternalError);
    TempDir tmp;
    EXPECT_THROW(write_reports(tmp.path(), r), InternalError);
    EXPECT_TRUE(entries(tmp.path()).empty());
  };
  Report r = good;
  r.frames[0].pairs[2].object_b = 3;
  all_writers_throw(r);
  std::ostringstream sink;
  EXPECT_THROW(write_pairs_csv(sink, r), InternalError);

  r = good;
  r.frames[0].degenerate[0].object = -1;
  all_writers_throw(r);

  r = good;
  r.frames[1].objects.pop_back();  // not one per object
  all_writers_throw(r);

  r = good;
  r.frames[0].checks[1].object_b = 5;
  all_writers_throw(r);

  r = good;
  r.frames[0].penetration[0].obstacle = 3;
  all_writers_throw(r);
}

TEST(ReportWrite, WritesTheThreeFilesAndNothingElse) {
  TempDir tmp;
  const fs::path out = tmp.path() / "nested" / "report";
  const Report r = hand_built_report();
  write_reports(out, r);
  EXPECT_EQ(entries(out), (std::vector<std::string>{"frames.csv", "pairs.csv", "report.json"}));
  std::ostringstream pairs;
  write_pairs_csv(pairs, r);
  EXPECT_EQ(read_all(out / "pairs.csv"), pairs.str());
  EXPECT_EQ(nlohmann::json::parse(read_all(out / "report.json")).at("schema"), "snag-report/2");

  // A second run replaces the files in place.
  Report r2 = r;
  r2.frames.resize(1);
  write_reports(out, r2);
  EXPECT_EQ(entries(out), (std::vector<std::string>{"frames.csv", "pairs.csv", "report.json"}));
  EXPECT_EQ(read_all(out / "pairs.csv"),
            "frame,face_a,face_b,kind,poly_a,poly_b\n12,0,4,touching,0,3\n");
}

TEST(ReportWrite, OutputPathIsAFile) {
  TempDir tmp;
  const fs::path out = tmp.path() / "not-a-dir";
  std::ofstream(out) << "x";
  EXPECT_THROW(write_reports(out, hand_built_report()), WriteError);
  EXPECT_THROW(prepare_output_dir(out), WriteError);
  EXPECT_EQ(read_all(out), "x");
  EXPECT_EQ(entries(tmp.path()), (std::vector<std::string>{"not-a-dir"}));
}

// The directories a run made for its reports go again unless it kept them; one that was there
// stays; a path through ".." is never removed.
TEST(ReportWrite, OutputDirectoryRemovesWhatItMadeUnlessKept) {
  TempDir tmp;
  { OutputDirectory dir(tmp.path() / "new" / "reports"); }
  EXPECT_EQ(entries(tmp.path()), std::vector<std::string>{});
  {
    OutputDirectory dir(tmp.path() / "kept" / "reports");
    dir.keep();
  }
  EXPECT_TRUE(fs::is_directory(tmp.path() / "kept" / "reports"));
  { OutputDirectory dir(tmp.path() / "kept" / "more/"); }
  EXPECT_EQ(entries(tmp.path() / "kept"), std::vector<std::string>{"reports"});
  { OutputDirectory dir(tmp.path() / "x" / ".." / "y"); }
  EXPECT_TRUE(fs::is_directory(tmp.path() / "y"));
  // Failing to prepare: a WriteError, as prepare_output_dir's.
  std::ofstream(tmp.path() / "file") << "x";
  EXPECT_THROW(OutputDirectory(tmp.path() / "file" / "below"), WriteError);
}

TEST(ReportWrite, OutputPathUnderAFile) {
  TempDir tmp;
  std::ofstream(tmp.path() / "file") << "x";
  const fs::path out = tmp.path() / "file" / "report";
  EXPECT_THROW(prepare_output_dir(out), WriteError);
  EXPECT_THROW(write_reports(out, hand_built_report()), WriteError);
  EXPECT_EQ(entries(tmp.path()), (std::vector<std::string>{"file"}));
}

TEST(ReportWrite, UnwritableDirectoryLeavesNothing) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: directory permissions do not stop writes";
  TempDir tmp;
  const fs::path out = tmp.path() / "ro";
  fs::create_directories(out);
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(prepare_output_dir(out), WriteError);
  EXPECT_THROW(write_reports(out, hand_built_report()), WriteError);
  fs::permissions(out, fs::perms::owner_all);
  EXPECT_TRUE(entries(out).empty());
}

// The same for root, whom permissions do not stop: /proc/self/fdinfo (Linux) is a directory
// in which nobody can create a file.
TEST(ReportWrite, ADirectoryThatTakesNoFilesIsAWriteErrorEvenForRoot) {
  const fs::path out = "/proc/self/fdinfo";
  if (!fs::is_directory(out)) GTEST_SKIP() << "no /proc/self/fdinfo here (not Linux)";
  try {
    prepare_output_dir(out);
    FAIL() << "prepare_output_dir accepted " << out;
  } catch (const WriteError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write into the output directory"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(write_reports(out, hand_built_report()), WriteError);
}

TEST(ReportWrite, FailureInALaterFileLeavesNoFileAndKeepsTheOldOnes) {
  // Works as root too: the failure comes from the writer, after earlier files were written
  // to their temporaries.
  TempDir tmp;
  std::ofstream(tmp.path() / "first.txt") << "old";
  const std::vector<OutputFile> files = {
      {"first.txt", [](std::ostream& out) { out << "new"; }},
      {"second.txt", [](std::ostream&) { throw std::runtime_error("writer failed"); }},
  };
  EXPECT_THROW(write_files_atomically(tmp.path(), files), std::runtime_error);
  EXPECT_EQ(entries(tmp.path()), (std::vector<std::string>{"first.txt"}));
  EXPECT_EQ(read_all(tmp.path() / "first.txt"), "old");
}

TEST(ReportWrite, StreamFailureIsAWriteError) {
  TempDir tmp;
  const std::vector<OutputFile> files = {
      {"bad.txt", [](std::ostream& out) { out.setstate(std::ios::badbit); }},
  };
  EXPECT_THROW(write_files_atomically(tmp.path(), files), WriteError);
  EXPECT_TRUE(entries(tmp.path()).empty());
}

}  // namespace
}  // namespace snag::report
