// `snag check` on scenes, end to end: --obstacle (still and moving), frames where nothing moved,
// scene files (roles, self, against, ignore, weld, and their errors), --split-groups, the
// penetration measure on a closed and an open cube, and the usage errors of the scene flags.
// Every case is hand-built, its pairs and depths worked out below.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/run_snag.h"

namespace snag::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct P {
  double x, y, z;
};
using Face = std::array<int, 3>;

/// An OBJ: `g NAME` before the first face of each run of one group (none when `groups` is
/// empty), vertices with 17 significant digits (read back exactly), 1-based faces.
std::string obj_text(const std::vector<P>& vertices, const std::vector<Face>& faces,
                     const std::vector<std::string>& groups = {}) {
  std::string text;
  char line[128];
  for (const P& v : vertices) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", v.x, v.y, v.z);
    text += line;
  }
  for (size_t f = 0; f < faces.size(); ++f) {
    if (!groups.empty() && (f == 0 || groups[f] != groups[f - 1])) text += "g " + groups[f] + "\n";
    text += "f " + std::to_string(faces[f][0] + 1) + " " + std::to_string(faces[f][1] + 1) + " " +
            std::to_string(faces[f][2] + 1) + "\n";
  }
  return text;
}

std::vector<P> moved(std::vector<P> vertices, P by) {
  for (P& v : vertices) v = {v.x + by.x, v.y + by.y, v.z + by.z};
  return vertices;
}

std::vector<P> joined(std::vector<P> a, const std::vector<P>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::vector<Face> joined(std::vector<Face> a, const std::vector<Face>& b, int vertex_offset) {
  for (Face f : b) a.push_back({f[0] + vertex_offset, f[1] + vertex_offset, f[2] + vertex_offset});
  return a;
}

// The pieces. The sheet: the square [0, 2] x [0, 2] of the y = 0 plane, face 0 where x >= z,
// face 1 where z >= x (they share the diagonal). A post: a triangle standing in the plane
// z = zc, its base at y = -1 from x = 1.2 to 1.8, its apex at (1.5, 1, zc); at y = 0 it spans
// x in [1.35, 1.65], so at zc = 0.5 or 0.25 it crosses sheet face 0 only, at zc = 1.5 both faces.
// A side post stands in the plane x = 0.5 (z from 1.2 to 1.8, apex z = 1.5) and crosses sheet
// face 1 only. A bar lies flat at y = -0.5 across the post at z = 0.5 (below the sheet).
const std::vector<P> sheet = {{0, 0, 0}, {2, 0, 0}, {2, 0, 2}, {0, 0, 2}};
const std::vector<Face> sheet_faces = {{0, 1, 2}, {0, 2, 3}};
std::vector<P> post(double zc) {
  return {{1.2, -1, zc}, {1.8, -1, zc}, {1.5, 1, zc}};
}
const std::vector<P> side_post = {{0.5, -1, 1.2}, {0.5, -1, 1.8}, {0.5, 1, 1.5}};
const std::vector<P> bar = {{1.4, -0.5, 0}, {1.6, -0.5, 0}, {1.5, -0.5, 1}};
const std::vector<Face> one_face = {{0, 1, 2}};

/// The unit cube [0, 1]^3, vertex x + 2y + 4z, each face's triangles counter-clockwise seen
/// from outside, in the order -z, +z, -y, +y, -x, +x (the +y face is triangles 6 and 7).
const std::vector<P> cube = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                             {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
const std::vector<Face> cube_faces = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                      {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                      {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};

std::string context(const RunResult& r) {
  return "stdout:\n" + r.out + "\nstderr:\n" + r.err;
}

/// One pair of report.json: (object_a, face_a, object_b, face_b, kind).
using Pair = std::tuple<std::string, int, std::string, int, std::string>;

std::vector<Pair> pairs_of(const json& frame) {
  std::vector<Pair> pairs;
  for (const json& p : frame.at("pairs"))
    pairs.emplace_back(p.at("object_a"), p.at("a"), p.at("object_b"), p.at("b"), p.at("kind"));
  return pairs;
}

/// The frames' pairs of a whole run, frame by frame.
std::vector<std::vector<Pair>> all_pairs(const json& report) {
  std::vector<std::vector<Pair>> frames;
  for (const json& f : report.at("frames")) frames.push_back(pairs_of(f));
  return frames;
}

const json& object_in(const json& list, const std::string& name) {
  for (const json& o : list)
    if (o.at("name") == name) return o;
  throw std::runtime_error("no object " + name + " in " + list.dump());
}

const json& check_in(const json& frame, const std::string& a, const std::string& b) {
  for (const json& c : frame.at("checks"))
    if (c.at("objects") == json::array({a, b})) return c;
  throw std::runtime_error("no check " + a + "/" + b + " in " + frame.at("checks").dump());
}

std::set<std::pair<std::string, std::string>> check_names(const json& frame) {
  std::set<std::pair<std::string, std::string>> names;
  for (const json& c : frame.at("checks")) names.emplace(c.at("objects")[0], c.at("objects")[1]);
  return names;
}

/// A run with `--out out` in `dir`; the report is read when the run wrote one.
struct SceneRun {
  RunResult result;
  json report;
  std::vector<std::vector<std::string>> frames_csv;
  std::string pairs_csv;
};

SceneRun run_in(const fs::path& dir, std::vector<std::string> args) {
  fs::remove_all(dir / "out");
  args.insert(args.begin(), "check");
  args.insert(args.end(), {"--out", "out", "--quiet"});
  SceneRun run;
  run.result = run_snag(args, dir);
  if (fs::exists(dir / "out" / "report.json")) {
    run.report = json::parse(read_text(dir / "out" / "report.json"));
    run.frames_csv = parse_csv(read_text(dir / "out" / "frames.csv"));
    run.pairs_csv = read_text(dir / "out" / "pairs.csv");
  }
  return run;
}

/// A column of frames.csv, by its header name, for every frame.
std::vector<std::string> column(const SceneRun& run, const std::string& name) {
  const auto& header = run.frames_csv.at(0);
  const auto at = std::find(header.begin(), header.end(), name);
  if (at == header.end()) throw std::runtime_error("frames.csv has no column " + name);
  std::vector<std::string> values;
  for (size_t i = 1; i < run.frames_csv.size(); ++i)
    values.push_back(run.frames_csv[i].at(static_cast<size_t>(at - header.begin())));
  return values;
}

/// No report file in `out` (the directory itself may or may not exist).
void expect_no_report(const fs::path& out) {
  for (const char* name : {"pairs.csv", "frames.csv", "report.json"})
    EXPECT_FALSE(fs::exists(out / name)) << (out / name);
  if (fs::is_directory(out)) EXPECT_EQ(directory_entries(out), std::vector<std::string>{});
}

// --obstacle ---------------------------------------------------------------------------------

TEST(SceneObstacle, StillObstacleIsBuiltOnce) {
  TempDir tmp;
  // The sheet rises 0.1 a frame through the post; the post's faces cross it at every height.
  for (int f = 1; f <= 3; ++f)
    write_text(tmp.path() / ("sheet.000" + std::to_string(f) + ".obj"),
               obj_text(moved(sheet, {0, 0.1 * (f - 1), 0}), sheet_faces));
  write_text(tmp.path() / "post.obj", obj_text(post(0.5), one_face));

  const SceneRun run =
      run_in(tmp.path(), {"sheet.%04d.obj", "--obstacle", "post.obj", "--rebuild", "never"});
  ASSERT_EQ(run.result.status, 1) << context(run.result);
  EXPECT_EQ(run.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "1,0,0,crossing,0,0,cloth,post\n"
            "2,0,0,crossing,0,0,cloth,post\n"
            "3,0,0,crossing,0,0,cloth,post\n");
  const json& inputs = run.report.at("inputs");
  const json& cloth = object_in(inputs.at("objects"), "cloth");
  const json& obstacle = object_in(inputs.at("objects"), "post");
  EXPECT_EQ(cloth.at("role"), "cloth");
  EXPECT_EQ(cloth.at("still"), false);
  EXPECT_EQ(obstacle.at("role"), "obstacle");
  EXPECT_EQ(obstacle.at("still"), true);
  EXPECT_EQ(obstacle.at("sequence"), "post.obj");
  EXPECT_EQ(obstacle.at("triangles"), 1);
  EXPECT_EQ(obstacle.at("vertices"), 3);

  const json& frames = run.report.at("frames");
  ASSERT_EQ(frames.size(), 3u);
  for (size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i + 1));
    const json& o = object_in(frames[i].at("objects"), "post");
    EXPECT_EQ(o.at("file"), "post.obj");
    EXPECT_EQ(o.at("rebuilt"), i == 0);
    if (i > 0) {
      EXPECT_EQ(o.at("moved"), false);
      EXPECT_EQ(object_in(frames[i].at("objects"), "cloth").at("moved"), true);
    }
    // The obstacle's own self-intersections are not checked.
    EXPECT_EQ(check_names(frames[i]), (std::set<std::pair<std::string, std::string>>{
                                          {"cloth", "cloth"}, {"cloth", "post"}}));
    EXPECT_EQ(check_in(frames[i], "cloth", "post").at("pairs"), 1);
    EXPECT_EQ(check_in(frames[i], "cloth", "post").at("reused"), false);
  }
  // A tree for the cloth and one for the post, each built once (--rebuild never).
  EXPECT_EQ(run.report.at("summary").at("builds"), 2);
  EXPECT_EQ(run.report.at("summary").at("rebuilds"), 0);
  EXPECT_EQ(column(run, "rebuilt"), (std::vector<std::string>{"1", "0", "0"}));
}

/// The sheet in every frame with a post that moves (body.%04d.obj): far away in frame 1, across
/// face 0 in frame 2, across the diagonal and both faces in frame 3.
void write_sheet_and_moving_post(const fs::path& dir) {
  const std::vector<std::vector<P>> posts = {moved(post(0.5), {5, 0, 0}), post(0.5), post(1.5)};
  for (int f = 1; f <= 3; ++f) {
    write_text(dir / ("sheet.000" + std::to_string(f) + ".obj"), obj_text(sheet, sheet_faces));
    write_text(dir / ("body.000" + std::to_string(f) + ".obj"), obj_text(posts[f - 1], one_face));
  }
}

TEST(SceneObstacle, MovingObstacleSequence) {
  TempDir tmp;
  // The sheet stays; the post crosses face 0 in frame 2 and both faces in frame 3.
  write_sheet_and_moving_post(tmp.path());
  const SceneRun run = run_in(tmp.path(), {"sheet.%04d.obj", "--obstacle", "body.%04d.obj"});
  ASSERT_EQ(run.result.status, 1) << context(run.result);
  EXPECT_EQ(run.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "2,0,0,crossing,0,0,cloth,body\n"
            "3,0,0,crossing,0,0,cloth,body\n"
            "3,1,0,crossing,1,0,cloth,body\n");
  const json& body = object_in(run.report.at("inputs").at("objects"), "body");
  EXPECT_EQ(body.at("still"), false);
  EXPECT_EQ(body.at("role"), "obstacle");
  const json& frames = run.report.at("frames");
  ASSERT_EQ(frames.size(), 3u);
  for (size_t i = 1; i < 3; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i + 1));
    const json& b = object_in(frames[i].at("objects"), "body");
    EXPECT_EQ(b.at("file"), "body.000" + std::to_string(i + 1) + ".obj");
    EXPECT_EQ(b.at("moved"), true);
    EXPECT_EQ(object_in(frames[i].at("objects"), "cloth").at("moved"), false);
    // The cloth did not move, so its self check is last frame's; the cross check is not.
    EXPECT_EQ(check_in(frames[i], "cloth", "cloth").at("reused"), true);
    EXPECT_EQ(check_in(frames[i], "cloth", "body").at("reused"), false);
  }
  EXPECT_EQ(column(run, "pairs"), (std::vector<std::string>{"0", "1", "2"}));
  EXPECT_EQ(column(run, "reused_pairs"), (std::vector<std::string>{"0", "0", "0"}));
}

TEST(SceneObstacle, ABaselineNamesEachFacesObject) {
  TempDir tmp;
  // As in MovingObstacleSequence: frame 2 has (cloth 0, body 0), frame 3 (cloth 0, body 0) and
  // (cloth 1, body 0). The baseline accepts the body's face 0 with the cloth's face 1, the
  // pair written body first; and the cloth's faces 0 and 1 with each other, which never meet.
  write_sheet_and_moving_post(tmp.path());
  write_text(tmp.path() / "accepted.csv",
             "object_b,object_a,frame,face_a,face_b\n"
             "cloth,body,*,0,1\n"
             "cloth,cloth,3,0,1\n");
  const SceneRun run = run_in(tmp.path(), {"sheet.%04d.obj", "--obstacle", "body.%04d.obj",
                                           "--baseline", "accepted.csv", "--junit", "out/s.xml"});
  ASSERT_EQ(run.result.status, 1) << context(run.result);
  EXPECT_EQ(run.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b,accepted\n"
            "2,0,0,crossing,0,0,cloth,body,0\n"
            "3,0,0,crossing,0,0,cloth,body,0\n"
            "3,1,0,crossing,1,0,cloth,body,1\n");
  EXPECT_EQ(column(run, "accepted"), (std::vector<std::string>{"0", "0", "1"}));
  EXPECT_EQ(run.report.at("inputs").at("baseline"), json({{"file", "accepted.csv"},
                                                          {"entries", 2},
                                                          {"left_out", 0},
                                                          {"checked", 2},
                                                          {"unmatched", 1},
                                                          {"unmatched_lines", {3}}}));
  EXPECT_EQ(run.report.at("summary").at("first_new_frame"), 2);
  // The JUnit report's failures name each face's object, as pairs.csv does.
  const std::string xml = read_text(tmp.path() / "out" / "s.xml");
  EXPECT_NE(xml.find("failures=\"2\""), std::string::npos) << xml;
  EXPECT_NE(xml.find(">frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
                     "3,0,0,crossing,0,0,cloth,body\n</failure>"),
            std::string::npos)
      << xml;

  // An object the run does not have is named, with the run's objects.
  write_text(tmp.path() / "other.csv",
             "frame,face_a,face_b,object_a,object_b\n1,0,0,cloth,floor\n");
  const SceneRun other = run_in(
      tmp.path(), {"sheet.%04d.obj", "--obstacle", "body.%04d.obj", "--baseline", "other.csv"});
  EXPECT_EQ(other.result.status, 3) << context(other.result);
  EXPECT_NE(other.result.err.find(
                "other.csv:2: object_b: 'floor' is not an object of this run (cloth, body)"),
            std::string::npos)
      << other.result.err;
  expect_no_report(tmp.path() / "out");
}

TEST(SceneObstacle, ObstacleSequenceMissingAFrameExitsThree) {
  TempDir tmp;
  for (int f = 1; f <= 3; ++f)
    write_text(tmp.path() / ("sheet.000" + std::to_string(f) + ".obj"),
               obj_text(sheet, sheet_faces));
  write_text(tmp.path() / "body.0001.obj", obj_text(post(0.5), one_face));
  write_text(tmp.path() / "body.0003.obj", obj_text(post(0.5), one_face));
  const SceneRun run = run_in(tmp.path(), {"sheet.%04d.obj", "--obstacle", "body.%04d.obj"});
  EXPECT_EQ(run.result.status, 3) << context(run.result);
  EXPECT_NE(run.result.err.find("body.%04d.obj"), std::string::npos) << run.result.err;
  EXPECT_NE(run.result.err.find("frame 2"), std::string::npos) << run.result.err;
  expect_no_report(tmp.path() / "out");
}

// Frames where nothing moved -------------------------------------------------------------------

TEST(SceneReuse, FrozenFrameReusesEveryCheck) {
  TempDir tmp;
  // The cloth: the sheet and, crossing its face 1, a side post of its own (a self pair (1, 2)),
  // against a still post crossing sheet face 0. Frame 1 is 0.1 higher; frame 3 is a copy of
  // frame 2, byte for byte.
  const std::vector<P> cloth = joined(sheet, side_post);
  const std::vector<Face> cloth_faces = joined(sheet_faces, one_face, 4);
  write_text(tmp.path() / "c.0001.obj", obj_text(moved(cloth, {0, 0.1, 0}), cloth_faces));
  write_text(tmp.path() / "c.0002.obj", obj_text(cloth, cloth_faces));
  fs::copy_file(tmp.path() / "c.0002.obj", tmp.path() / "c.0003.obj");
  write_text(tmp.path() / "post.obj", obj_text(post(0.5), one_face));

  const SceneRun run = run_in(tmp.path(), {"c.%04d.obj", "--obstacle", "post.obj"});
  ASSERT_EQ(run.result.status, 1) << context(run.result);
  const json& frames = run.report.at("frames");
  ASSERT_EQ(frames.size(), 3u);
  // In scene order: object_a, face_a, object_b, face_b.
  const std::vector<Pair> expected = {{"cloth", 0, "post", 0, "crossing"},
                                      {"cloth", 1, "cloth", 2, "crossing"}};
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(pairs_of(frames[i]), expected) << "frame " << i + 1;

  for (size_t i = 0; i < 2; ++i)
    for (const json& c : frames[i].at("checks")) EXPECT_EQ(c.at("reused"), false) << c.dump();
  ASSERT_EQ(frames[2].at("checks").size(), 2u);
  for (const json& c : frames[2].at("checks")) EXPECT_EQ(c.at("reused"), true) << c.dump();
  for (const json& o : frames[2].at("objects")) EXPECT_EQ(o.at("moved"), false) << o.dump();
  EXPECT_EQ(column(run, "pairs"), (std::vector<std::string>{"2", "2", "2"}));
  EXPECT_EQ(column(run, "reused_pairs"), (std::vector<std::string>{"0", "0", "2"}));
  EXPECT_EQ(run.report.at("summary").at("reused_pairs"), 2);

  // pairs.csv: frame 3's rows are frame 2's.
  std::vector<std::string> rows2, rows3;
  for (const auto& row : parse_csv(run.pairs_csv)) {
    if (row.at(0) == "frame") continue;
    std::string rest;
    for (size_t k = 1; k < row.size(); ++k) rest += "," + row[k];
    if (row[0] == "2") rows2.push_back(rest);
    if (row[0] == "3") rows3.push_back(rest);
  }
  EXPECT_EQ(rows2.size(), 2u);
  EXPECT_EQ(rows3, rows2);
}

// --scene -------------------------------------------------------------------------------------

/// The sheet (cloth) and a body of two faces crossing each other: the post (crossing sheet
/// face 0) and the bar (below the sheet).
void write_sheet_and_body(const fs::path& dir) {
  fs::create_directories(dir);
  write_text(dir / "sheet.obj", obj_text(sheet, sheet_faces));
  write_text(dir / "body.obj", obj_text(joined(post(0.5), bar), {{0, 1, 2}, {3, 4, 5}}));
}

TEST(SceneFile, RolesAndSelfOnAnObstacle) {
  TempDir tmp;
  // Sequences are relative to the scene file's directory, not the working directory.
  write_sheet_and_body(tmp.path() / "shot");
  write_text(tmp.path() / "shot" / "plain.json", R"({"schema": "snag-scene/1", "objects": [
    {"name": "shirt", "sequence": "sheet.obj"},
    {"name": "body", "sequence": "body.obj", "role": "obstacle"}]})");
  write_text(tmp.path() / "shot" / "self.json", R"({"objects": [
    {"name": "shirt", "sequence": "sheet.obj"},
    {"name": "body", "sequence": "body.obj", "role": "obstacle", "self": true}]})");

  const SceneRun plain = run_in(tmp.path(), {"--scene", "shot/plain.json"});
  ASSERT_EQ(plain.result.status, 1) << context(plain.result);
  const json& objects = plain.report.at("inputs").at("objects");
  EXPECT_EQ(object_in(objects, "shirt").at("role"), "cloth");  // the default role
  EXPECT_EQ(object_in(objects, "shirt").at("sequence"), "shot/sheet.obj");
  EXPECT_EQ(object_in(objects, "body").at("role"), "obstacle");
  EXPECT_EQ(plain.report.at("inputs").at("sequence"), "shot/plain.json");
  EXPECT_EQ(all_pairs(plain.report),
            (std::vector<std::vector<Pair>>{{{"shirt", 0, "body", 0, "crossing"}}}));
  EXPECT_EQ(check_names(plain.report.at("frames")[0]),
            (std::set<std::pair<std::string, std::string>>{{"shirt", "shirt"}, {"shirt", "body"}}));
  EXPECT_EQ(column(plain, "file"), std::vector<std::string>{"shot/sheet.obj"});

  const SceneRun self = run_in(tmp.path(), {"--scene", "shot/self.json"});
  ASSERT_EQ(self.result.status, 1) << context(self.result);
  EXPECT_EQ(all_pairs(self.report),
            (std::vector<std::vector<Pair>>{
                {{"shirt", 0, "body", 0, "crossing"}, {"body", 0, "body", 1, "crossing"}}}));
  EXPECT_EQ(check_in(self.report.at("frames")[0], "body", "body").at("pairs"), 1);
  EXPECT_EQ(self.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "0,0,0,crossing,0,0,shirt,body\n"  // one file, no digits: frame 0
            "0,0,1,crossing,0,1,body,body\n");
}

TEST(SceneFile, AgainstChoosesTheChecks) {
  TempDir tmp;
  write_text(tmp.path() / "sheet.obj", obj_text(sheet, sheet_faces));
  write_text(tmp.path() / "post.obj", obj_text(post(0.5), one_face));  // crosses sheet face 0
  write_text(tmp.path() / "side.obj", obj_text(side_post, one_face));  // crosses sheet face 1
  const auto scene = [](const std::string& shirt_extra, const std::string& side_extra) {
    return R"({"objects": [{"name": "shirt", "sequence": "sheet.obj")" + shirt_extra +
           R"(}, {"name": "post", "sequence": "post.obj", "role": "obstacle"},
              {"name": "side", "sequence": "side.obj", "role": "obstacle")" +
           side_extra + "}]}";
  };
  using Checks = std::set<std::pair<std::string, std::string>>;
  struct Case {
    std::string name, shirt_extra, side_extra;
    std::vector<Pair> pairs;
    Checks checks;
  };
  const std::vector<Case> cases = {
      {"every obstacle by default",
       "",
       "",
       {{"shirt", 0, "post", 0, "crossing"}, {"shirt", 1, "side", 0, "crossing"}},
       {{"shirt", "shirt"}, {"shirt", "post"}, {"shirt", "side"}}},
      {"the cloth lists post only",
       R"(, "against": ["post"])",
       "",
       {{"shirt", 0, "post", 0, "crossing"}},
       {{"shirt", "shirt"}, {"shirt", "post"}}},
      {"side lists the cloth (checks are symmetric)",
       R"(, "against": ["post"])",
       R"(, "against": ["shirt"])",
       {{"shirt", 0, "post", 0, "crossing"}, {"shirt", 1, "side", 0, "crossing"}},
       {{"shirt", "shirt"}, {"shirt", "post"}, {"shirt", "side"}}},
      {"none, and no self check", R"(, "against": [], "self": false)", "", {}, {}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write_text(tmp.path() / "scene.json", scene(c.shirt_extra, c.side_extra));
    const SceneRun run = run_in(tmp.path(), {"--scene", "scene.json"});
    ASSERT_EQ(run.result.status, c.pairs.empty() ? 0 : 1) << context(run.result);
    EXPECT_EQ(pairs_of(run.report.at("frames")[0]), c.pairs);
    EXPECT_EQ(check_names(run.report.at("frames")[0]), c.checks);
  }
}

TEST(SceneFile, IgnoreRulesLeaveOutPairsOfNamedGroups) {
  TempDir tmp;
  // Cloth groups: collar (sheet face 0), sleeve (face 1), patch (face 2, a side post at x = 0.3
  // across the sleeve: a self pair). Body groups: neck (a post at z = 0.5, across the collar),
  // arm (a post at z = 0.25, across the collar, and the side post, across the sleeve).
  const std::vector<P> patch = moved(side_post, {-0.2, 0, 0});
  write_text(tmp.path() / "shirt.obj",
             obj_text(joined(sheet, patch), joined(sheet_faces, one_face, 4),
                      {"collar", "sleeve", "patch"}));
  write_text(tmp.path() / "body.obj",
             obj_text(joined(joined(post(0.5), post(0.25)), side_post),
                      {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}}, {"neck", "arm", "arm"}));
  const auto scene = [](const std::string& shirt_extra, const std::string& body_extra) {
    return R"({"objects": [{"name": "shirt", "sequence": "shirt.obj")" + shirt_extra +
           R"(}, {"name": "body", "sequence": "body.obj", "role": "obstacle")" + body_extra + "}]}";
  };
  // In report order: object_a, face_a, object_b, face_b (shirt before body).
  const Pair collar_neck{"shirt", 0, "body", 0, "crossing"};
  const Pair collar_arm{"shirt", 0, "body", 1, "crossing"};
  const Pair sleeve_patch{"shirt", 1, "shirt", 2, "crossing"};
  const Pair sleeve_arm{"shirt", 1, "body", 2, "crossing"};
  struct Case {
    std::string name, shirt_extra, body_extra;
    std::vector<Pair> pairs;
  };
  const std::vector<Case> cases = {
      {"no rule", "", "", {collar_neck, collar_arm, sleeve_patch, sleeve_arm}},
      {"collar/neck on the cloth",
       R"(, "ignore": [["collar", "neck"]])",
       "",
       {collar_arm, sleeve_patch, sleeve_arm}},
      {"neck/collar on the obstacle",
       "",
       R"(, "ignore": [["neck", "collar"]])",
       {collar_arm, sleeve_patch, sleeve_arm}},
      {"collar/* on the cloth", R"(, "ignore": [["collar", "*"]])", "", {sleeve_patch, sleeve_arm}},
      {"neck/collar on the cloth: its first group is the cloth's",
       R"(, "ignore": [["neck", "collar"]])",
       "",
       {collar_neck, collar_arm, sleeve_patch, sleeve_arm}},
      {"sleeve/patch: two groups of one object",
       R"(, "ignore": [["sleeve", "patch"]])",
       "",
       {collar_neck, collar_arm, sleeve_arm}},
      {"patch/sleeve: either order within one object",
       R"(, "ignore": [["patch", "sleeve"]])",
       "",
       {collar_neck, collar_arm, sleeve_arm}},
      {"sleeve/* and collar/arm",
       R"(, "ignore": [["sleeve", "*"], ["collar", "arm"]])",
       "",
       {collar_neck}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write_text(tmp.path() / "scene.json", scene(c.shirt_extra, c.body_extra));
    const SceneRun run = run_in(tmp.path(), {"--scene", "scene.json"});
    ASSERT_EQ(run.result.status, 1) << context(run.result);
    const json& frame = run.report.at("frames")[0];
    EXPECT_EQ(pairs_of(frame), c.pairs);
    // The checks count what is reported, not what was found.
    const auto count = [&](const std::string& b) {
      return std::count_if(c.pairs.begin(), c.pairs.end(),
                           [&](const Pair& p) { return std::get<2>(p) == b; });
    };
    EXPECT_EQ(check_in(frame, "shirt", "shirt").at("pairs"), count("shirt"));
    EXPECT_EQ(check_in(frame, "shirt", "body").at("pairs"), count("body"));
    EXPECT_EQ(column(run, "pairs"), std::vector<std::string>{std::to_string(c.pairs.size())});
    EXPECT_EQ(run.report.at("summary").at("pairs"), static_cast<int>(c.pairs.size()));
  }
}

TEST(SceneFile, WeldIsPerObject) {
  TempDir tmp;
  // Each seam: two flat triangles on either side of one edge, with separate (coincident)
  // vertices there. Unwelded, they touch along that edge; welded, they are neighbours.
  const std::vector<P> seam = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  const std::vector<Face> seam_faces = {{0, 1, 2}, {3, 4, 5}};
  write_text(tmp.path() / "left.obj", obj_text(seam, seam_faces));
  write_text(tmp.path() / "right.obj", obj_text(moved(seam, {5, 0, 0}), seam_faces));
  write_text(tmp.path() / "scene.json", R"({"objects": [
    {"name": "left", "sequence": "left.obj", "weld": 1e-9},
    {"name": "right", "sequence": "right.obj"}]})");
  const SceneRun run = run_in(tmp.path(), {"--scene", "scene.json"});
  ASSERT_EQ(run.result.status, 0) << context(run.result);  // touching only
  EXPECT_EQ(all_pairs(run.report),
            (std::vector<std::vector<Pair>>{{{"right", 0, "right", 1, "touching"}}}));
  const json& objects = run.report.at("inputs").at("objects");
  EXPECT_EQ(object_in(objects, "left").at("weld"), 1e-9);
  EXPECT_TRUE(object_in(objects, "right").at("weld").is_null());
  EXPECT_EQ(run.report.at("inputs").at("welded_vertices"), 2);
  EXPECT_EQ(run.report.at("inputs").at("coincident_vertices"), 2);  // right's, unwelded
  // Two cloths are not checked against each other unless one lists the other.
  EXPECT_EQ(check_names(run.report.at("frames")[0]),
            (std::set<std::pair<std::string, std::string>>{{"left", "left"}, {"right", "right"}}));
}

TEST(SceneFile, ErrorsNameFileLineAndKeyAndWriteNoReport) {
  TempDir tmp;
  write_sheet_and_body(tmp.path());
  struct Case {
    std::string name, text, expected;  // expected: what the message must contain
  };
  const std::vector<Case> cases = {
      {"unknown key",
       "{\"objects\": [\n"
       "  {\"name\": \"shirt\", \"sequence\": \"sheet.obj\"},\n"
       "  {\"name\": \"body\", \"sequence\": \"body.obj\",\n"
       "   \"colour\": \"red\"}]}\n",
       "scene.json:4: objects[1].colour"},
      {"bad role",
       "{\"objects\": [\n"
       "  {\"name\": \"shirt\", \"sequence\": \"sheet.obj\"},\n"
       "  {\"name\": \"body\", \"sequence\": \"body.obj\", \"role\": \"body\"}]}\n",
       "scene.json:3: objects[1].role"},
      {"missing sequence",
       "{\"objects\": [\n"
       "  {\"name\": \"shirt\", \"sequence\": \"sheet.obj\"},\n"
       "  {\"name\": \"body\", \"role\": \"obstacle\"}]}\n",
       "scene.json:3: objects[1]: missing key \"sequence\""},
      {"against a name no object has",
       "{\"objects\": [\n"
       "  {\"name\": \"shirt\", \"sequence\": \"sheet.obj\",\n"
       "   \"against\": [\"bdy\"]},\n"
       "  {\"name\": \"body\", \"sequence\": \"body.obj\", \"role\": \"obstacle\"}]}\n",
       "scene.json:3: objects[0].against"},
      {"no cloth",
       "{\"objects\": [\n"
       "  {\"name\": \"body\", \"sequence\": \"body.obj\", \"role\": \"obstacle\"}]}\n",
       "scene.json:1: objects"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write_text(tmp.path() / "scene.json", c.text);
    const SceneRun run = run_in(tmp.path(), {"--scene", "scene.json"});
    EXPECT_EQ(run.result.status, 3) << context(run.result);
    EXPECT_NE(run.result.err.find(c.expected), std::string::npos) << run.result.err;
    expect_no_report(tmp.path() / "out");
  }
  // A sequence with no files: the message names it, resolved against the scene's directory.
  fs::create_directories(tmp.path() / "shot");
  write_sheet_and_body(tmp.path() / "shot");
  write_text(tmp.path() / "shot" / "scene.json", R"({"objects": [
    {"name": "shirt", "sequence": "sheet.obj"},
    {"name": "body", "sequence": "nobody.%04d.obj", "role": "obstacle"}]})");
  const SceneRun run = run_in(tmp.path(), {"--scene", "shot/scene.json"});
  EXPECT_EQ(run.result.status, 3) << context(run.result);
  EXPECT_NE(run.result.err.find("shot/nobody.%04d.obj"), std::string::npos) << run.result.err;
  expect_no_report(tmp.path() / "out");
}

// --split-groups -----------------------------------------------------------------------------

TEST(SceneSplitGroups, ObstacleGroupIsNotCheckedAgainstItself) {
  TempDir tmp;
  // One file: group body (the post and the bar, crossing each other; faces 0 and 1), then
  // group shirt (the sheet; faces 2 and 3), the post across shirt face 2.
  write_text(tmp.path() / "avatar.obj", obj_text(joined(joined(post(0.5), bar), sheet),
                                                 {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {6, 8, 9}},
                                                 {"body", "body", "shirt", "shirt"}));

  const SceneRun obstacle =
      run_in(tmp.path(), {"avatar.obj", "--split-groups", "--obstacle-group", "body"});
  ASSERT_EQ(obstacle.result.status, 1) << context(obstacle.result);
  // Ids are the file's; objects in the file's group order (body first).
  EXPECT_EQ(obstacle.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "0,0,2,crossing,0,2,body,shirt\n");  // one file, no digits: frame 0
  const json& objects = obstacle.report.at("inputs").at("objects");
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].at("name"), "body");
  EXPECT_EQ(objects[0].at("role"), "obstacle");
  EXPECT_EQ(objects[0].at("group"), "body");
  EXPECT_EQ(objects[1].at("name"), "shirt");
  EXPECT_EQ(objects[1].at("role"), "cloth");
  EXPECT_EQ(objects[1].at("group"), "shirt");
  EXPECT_EQ(check_names(obstacle.report.at("frames")[0]),
            (std::set<std::pair<std::string, std::string>>{{"shirt", "shirt"}, {"body", "shirt"}}));

  const SceneRun cloth = run_in(tmp.path(), {"avatar.obj", "--split-groups"});
  ASSERT_EQ(cloth.result.status, 1) << context(cloth.result);
  EXPECT_EQ(cloth.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "0,0,1,crossing,0,1,body,body\n"
            "0,0,2,crossing,0,2,body,shirt\n");
  EXPECT_EQ(object_in(cloth.report.at("inputs").at("objects"), "body").at("role"), "cloth");
}

TEST(SceneSplitGroups, FacesOfNoGroupAndOfAGroupNamedDefaultAreOneObject) {
  // The post (face 0) before any group line, the bar (face 1) in a group named "default", the
  // sheet (faces 2 and 3) in group shirt: faces of no group are in "default" too, so the post
  // and the bar are one object, checked against itself (they cross) and against the shirt.
  TempDir tmp;
  std::string text =
      obj_text(joined(joined(post(0.5), bar), sheet), {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {6, 8, 9}});
  const size_t second_face = text.find("f 4 5 6\n"), third_face = text.find("f 7 8 9\n");
  ASSERT_NE(second_face, std::string::npos);
  ASSERT_NE(third_face, std::string::npos);
  text.insert(third_face, "g shirt\n");
  text.insert(second_face, "g default\n");
  write_text(tmp.path() / "avatar.obj", text);

  const SceneRun run = run_in(tmp.path(), {"avatar.obj", "--split-groups"});
  ASSERT_EQ(run.result.status, 1) << context(run.result);
  EXPECT_EQ(run.pairs_csv,
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "0,0,1,crossing,0,1,default,default\n"
            "0,0,2,crossing,0,2,default,shirt\n");
  const json& objects = run.report.at("inputs").at("objects");
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].at("group"), "default");
  EXPECT_EQ(objects[1].at("group"), "shirt");
}

TEST(SceneSplitGroups, NothingToCheckIsAnErrorThatSaysWhy) {
  // Found by fuzzing: both were the usage error "a scene needs at least one cloth", naming
  // neither the file nor the options.
  TempDir tmp;
  write_text(tmp.path() / "empty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");  // no faces
  const SceneRun empty = run_in(tmp.path(), {"empty.obj", "--split-groups"});
  EXPECT_EQ(empty.result.status, 3) << context(empty.result);
  EXPECT_NE(empty.result.err.find("empty.obj: has no faces, so no groups for --split-groups"),
            std::string::npos)
      << context(empty.result);
  EXPECT_FALSE(fs::exists(tmp.path() / "out" / "report.json"));

  write_text(tmp.path() / "body.obj",
             obj_text(joined(post(0.5), bar), {{0, 1, 2}, {3, 4, 5}}, {"body", "body"}));
  const SceneRun all =
      run_in(tmp.path(), {"body.obj", "--split-groups", "--obstacle-group", "body"});
  EXPECT_EQ(all.result.status, 2) << context(all.result);
  EXPECT_NE(all.result.err.find("--obstacle-group names every group of body.obj (body); at least "
                                "one must be a cloth"),
            std::string::npos)
      << context(all.result);
}

TEST(SceneSplitGroups, TheSummaryNamesTheFirstObjectsAndCountsTheRest) {
  // Fourteen one-triangle groups side by side: the summary names twelve, report.json all.
  TempDir tmp;
  std::vector<P> vertices;
  std::vector<Face> faces;
  std::vector<std::string> groups;
  for (int g = 0; g < 14; ++g) {
    const int v = static_cast<int>(vertices.size());
    for (const P& p : std::vector<P>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})
      vertices.push_back({p.x + 3.0 * g, p.y, p.z});
    faces.push_back({v, v + 1, v + 2});
    groups.push_back("panel" + std::to_string(g));
  }
  write_text(tmp.path() / "panels.obj", obj_text(vertices, faces, groups));
  fs::remove_all(tmp.path() / "out");
  const RunResult run =
      run_snag({"check", "panels.obj", "--split-groups", "--out", "out"}, tmp.path());
  ASSERT_EQ(run.status, 0) << context(run);
  EXPECT_NE(run.out.find("panel11 (cloth"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("panel12 (cloth"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(", and 2 more (report.json lists them)"), std::string::npos) << run.out;
  EXPECT_EQ(
      json::parse(read_text(tmp.path() / "out" / "report.json")).at("inputs").at("objects").size(),
      14u);
  // Without --out there is no report to point to.
  const RunResult bare = run_snag({"check", "panels.obj", "--split-groups"}, tmp.path());
  ASSERT_EQ(bare.status, 0) << context(bare);
  EXPECT_NE(bare.out.find(", and 2 more\n"), std::string::npos) << bare.out;
}

// Penetration ----------------------------------------------------------------------------------

/// A cloth of two triangles: (a) three vertices inside the unit cube at depths 0.5 (its
/// centre), 0.2 (0.2 from the x = 0 face) and 0.05 (0.05 below the top), (b) one vertex exactly
/// on the top face (on the surface: not inside) and two outside.
const std::vector<P> probe = {{0.5, 0.5, 0.5}, {0.2, 0.4, 0.5}, {0.5, 0.95, 0.5},
                              {0.5, 1, 0.3},   {3, 3, 3},       {-1, 0.5, 0.5}};
const std::vector<Face> probe_faces = {{0, 1, 2}, {3, 4, 5}};

TEST(ScenePenetration, ClosedCubeDepthsByHand) {
  TempDir tmp;
  write_text(tmp.path() / "probe.obj", obj_text(probe, probe_faces));
  write_text(tmp.path() / "cube.obj", obj_text(cube, cube_faces));
  // The same cube with every face turned inwards: its inside is still the cube.
  std::vector<Face> inward = cube_faces;
  for (Face& f : inward) std::swap(f[1], f[2]);
  write_text(tmp.path() / "inward.obj", obj_text(cube, inward));

  for (const char* obstacle : {"cube.obj", "inward.obj"}) {
    SCOPED_TRACE(obstacle);
    const SceneRun run = run_in(tmp.path(), {"probe.obj", "--obstacle", obstacle});
    ASSERT_TRUE(run.result.status == 0 || run.result.status == 1) << context(run.result);
    const std::string name = fs::path(obstacle).stem().string();
    EXPECT_EQ(object_in(run.report.at("inputs").at("objects"), name).at("closed"), "closed");
    EXPECT_TRUE(object_in(run.report.at("inputs").at("objects"), "cloth").at("closed").is_null());
    const json& penetration = run.report.at("frames")[0].at("penetration");
    ASSERT_EQ(penetration.size(), 1u) << penetration.dump();
    const json& p = penetration[0];
    EXPECT_EQ(p.at("cloth"), "cloth");
    EXPECT_EQ(p.at("obstacle"), name);
    EXPECT_EQ(p.at("vertices"), 6);
    EXPECT_EQ(p.at("inside"), 3);
    EXPECT_DOUBLE_EQ(p.at("ratio").get<double>(), 0.5);
    EXPECT_NEAR(p.at("max_depth").get<double>(), 0.5, 1e-12);
    EXPECT_NEAR(p.at("mean_depth").get<double>(), (0.5 + 0.2 + 0.05) / 3, 1e-12);
    EXPECT_NEAR(p.at("p95_depth").get<double>(), 0.5, 1e-12);  // rank ceil(0.95 * 3) = 3
    EXPECT_EQ(column(run, "inside_vertices"), std::vector<std::string>{"3"});
    EXPECT_EQ(column(run, "max_depth"), std::vector<std::string>{"0.500000"});
    EXPECT_NEAR(run.report.at("summary").at("max_depth").get<double>(), 0.5, 1e-12);
  }
}

TEST(ScenePenetration, FollowsAMovingObstacleAndCarriesOverStillFrames) {
  TempDir tmp;
  // The probe's inside triangle, 0.1 lower from frame 2 on; the cube still until frame 4, when
  // it moves 0.1 along +x. Depths by hand: frame 1 (0.5, 0.2, 0.05); frames 2 and 3, nothing
  // moved in 3, (0.4, 0.2, 0.15); frame 4, (0.4, 0.1, 0.15), x - 0.1 now the nearest for the
  // second vertex.
  const std::vector<P> inside(probe.begin(), probe.begin() + 3);
  const std::vector<P> lower = moved(inside, {0, -0.1, 0});
  write_text(tmp.path() / "c.0001.obj", obj_text(inside, one_face));
  for (const char* f : {"c.0002.obj", "c.0003.obj", "c.0004.obj"})
    write_text(tmp.path() / f, obj_text(lower, one_face));
  for (const char* f : {"b.0001.obj", "b.0002.obj", "b.0003.obj"})
    write_text(tmp.path() / f, obj_text(cube, cube_faces));
  write_text(tmp.path() / "b.0004.obj", obj_text(moved(cube, {0.1, 0, 0}), cube_faces));

  const SceneRun run = run_in(tmp.path(), {"c.%04d.obj", "--obstacle", "b.%04d.obj"});
  ASSERT_EQ(run.result.status, 0) << context(run.result);
  const std::vector<std::array<double, 3>> depths = {
      {0.5, 0.2, 0.05}, {0.4, 0.2, 0.15}, {0.4, 0.2, 0.15}, {0.4, 0.1, 0.15}};
  const json& frames = run.report.at("frames");
  ASSERT_EQ(frames.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i + 1));
    ASSERT_EQ(frames[i].at("penetration").size(), 1u);
    const json& p = frames[i].at("penetration")[0];
    EXPECT_EQ(p.at("inside"), 3);
    EXPECT_DOUBLE_EQ(p.at("ratio").get<double>(), 1.0);
    const auto& d = depths[i];
    EXPECT_NEAR(p.at("max_depth").get<double>(), *std::max_element(d.begin(), d.end()), 1e-12);
    EXPECT_NEAR(p.at("mean_depth").get<double>(), (d[0] + d[1] + d[2]) / 3, 1e-12);
    EXPECT_NEAR(p.at("p95_depth").get<double>(), *std::max_element(d.begin(), d.end()), 1e-12);
  }
  EXPECT_EQ(object_in(frames[2].at("objects"), "b").at("moved"), false);
  EXPECT_EQ(object_in(frames[2].at("objects"), "cloth").at("moved"), false);
  EXPECT_EQ(object_in(frames[3].at("objects"), "b").at("moved"), true);
  EXPECT_EQ(column(run, "max_depth"),
            (std::vector<std::string>{"0.500000", "0.400000", "0.400000", "0.400000"}));
  EXPECT_NEAR(run.report.at("summary").at("max_depth").get<double>(), 0.5, 1e-12);
}

TEST(ScenePenetration, OpenObstacleIsNamedAndNotMeasured) {
  TempDir tmp;
  write_text(tmp.path() / "probe.obj", obj_text(probe, probe_faces));
  // The cube less its +y face (triangles 6 and 7): a hole bounded by vertices 2, 3, 6, 7.
  std::vector<Face> open = cube_faces;
  open.erase(open.begin() + 6, open.begin() + 8);
  write_text(tmp.path() / "box.obj", obj_text(cube, open));

  const SceneRun run = run_in(tmp.path(), {"probe.obj", "--obstacle", "box.obj"});
  ASSERT_TRUE(run.result.status == 0 || run.result.status == 1) << context(run.result);
  const json& closed = object_in(run.report.at("inputs").at("objects"), "box").at("closed");
  ASSERT_TRUE(closed.is_string()) << closed.dump();
  const std::string why = closed.get<std::string>();
  EXPECT_NE(why, "closed");
  EXPECT_NE(why.find("hole"), std::string::npos) << why;
  std::smatch edge;
  ASSERT_TRUE(std::regex_search(why, edge, std::regex(R"(edge \((\d+), (\d+)\))"))) << why;
  const std::set<int> rim = {2, 3, 6, 7};
  EXPECT_TRUE(rim.count(std::stoi(edge[1])) && rim.count(std::stoi(edge[2])))
      << why << ": not an edge of the missing face";
  EXPECT_TRUE(run.report.at("frames")[0].at("penetration").empty())
      << run.report.at("frames")[0].at("penetration").dump();
  EXPECT_EQ(column(run, "inside_vertices"), std::vector<std::string>{"0"});
  EXPECT_EQ(column(run, "max_depth"), std::vector<std::string>{"0.000000"});
}

// Disabled: these fail on snag as it is (see each comment); enable them once fixed.

// The closedness test and the penetration meter see the obstacle as its "weld" joins it: a
// closed body exported with split vertices (a triangle soup, as PLY exports with per-face
// attributes often are) is closed with "weld": 1e-9, and its penetration is measured.
TEST(ScenePenetration, WeldedSoupObstacleIsClosed) {
  TempDir tmp;
  std::vector<P> soup;
  std::vector<Face> soup_faces;
  for (const Face& f : cube_faces) {
    const int n = static_cast<int>(soup.size());
    for (int k = 0; k < 3; ++k) soup.push_back(cube[f[k]]);
    soup_faces.push_back({n, n + 1, n + 2});
  }
  write_text(tmp.path() / "soup.obj", obj_text(soup, soup_faces));
  write_text(tmp.path() / "probe.obj", obj_text(probe, probe_faces));
  write_text(tmp.path() / "scene.json", R"({"objects": [
    {"name": "cloth", "sequence": "probe.obj"},
    {"name": "body", "sequence": "soup.obj", "role": "obstacle", "weld": 1e-9}]})");
  const SceneRun run = run_in(tmp.path(), {"--scene", "scene.json"});
  ASSERT_TRUE(run.result.status == 0 || run.result.status == 1) << context(run.result);
  EXPECT_EQ(object_in(run.report.at("inputs").at("objects"), "body").at("closed"), "closed");
  const json& penetration = run.report.at("frames")[0].at("penetration");
  ASSERT_EQ(penetration.size(), 1u);
  EXPECT_EQ(penetration[0].at("inside"), 3);
}

// An obstacle that is one group of a file: the reason it is not closed names the file's
// vertex ids (as pairs and degenerate faces do), and says that its triangles are counted
// within the group (triangle 0 of this file is the shirt's).
TEST(ScenePenetration, OpenGroupObstacleNamesTheFilesVertexIds) {
  TempDir tmp;
  // The shirt first (file vertices 0-2, face 0), then the open cube (file vertices 3-10,
  // faces 1-10); the hole's rim is cube vertices 2, 3, 6, 7: file vertices 5, 6, 9, 10.
  std::vector<Face> open = cube_faces;
  open.erase(open.begin() + 6, open.begin() + 8);
  const std::vector<P> inside(probe.begin(), probe.begin() + 3);
  std::vector<std::string> groups = {"shirt"};
  groups.resize(1 + open.size(), "box");
  write_text(tmp.path() / "a.obj",
             obj_text(joined(inside, cube), joined(one_face, open, 3), groups));
  const SceneRun run = run_in(tmp.path(), {"a.obj", "--split-groups", "--obstacle-group", "box"});
  ASSERT_TRUE(run.result.status == 0 || run.result.status == 1) << context(run.result);
  const std::string why =
      object_in(run.report.at("inputs").at("objects"), "box").at("closed").get<std::string>();
  std::smatch edge;
  ASSERT_TRUE(std::regex_search(why, edge, std::regex(R"(edge \((\d+), (\d+)\))"))) << why;
  const std::set<int> rim = {5, 6, 9, 10};
  EXPECT_TRUE(rim.count(std::stoi(edge[1])) && rim.count(std::stoi(edge[2]))) << why;
  EXPECT_NE(why.find("triangles are counted within the group"), std::string::npos) << why;
}

// Usage errors ---------------------------------------------------------------------------------

TEST(SceneUsage, ConflictingFlagsExitTwo) {
  TempDir tmp;
  write_sheet_and_body(tmp.path());
  write_text(tmp.path() / "scene.json", R"({"objects": [
    {"name": "shirt", "sequence": "sheet.obj"}]})");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"sheet.obj", "--scene", "scene.json"},
        {"sheet.obj", "--obstacle-group", "body"},
        {"--scene", "scene.json", "--obstacle", "body.obj"},
        {"--scene", "scene.json", "--weld", "1e-6"}}) {
    std::string line;
    for (const std::string& a : args) line += a + " ";
    SCOPED_TRACE(line);
    const SceneRun run = run_in(tmp.path(), args);
    EXPECT_EQ(run.result.status, 2) << context(run.result);
    EXPECT_NE(run.result.err.find("snag: error:"), std::string::npos) << run.result.err;
    expect_no_report(tmp.path() / "out");
  }
}

}  // namespace
}  // namespace snag::test
