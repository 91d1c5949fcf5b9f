// The committed expected reports of samples/drape: snag's reports must match them, and they
// must match CGAL's self_intersections, frame by frame, so they are not merely a recording of
// snag's own output. Likewise samples/drape-scene-expected, the drape against a sphere it goes
// into (samples/drape-scene.json): its cloth-sphere pairs against CGAL's pairs between two
// meshes, its penetration against a winding number and point-triangle distances.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/run_snag.h"
#include "snag/detect/topology.h"
#include "snag/io/read_mesh.h"
#include "snag/seq/sequence.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"
#include "test_paths.h"

namespace snag::test {
namespace {

namespace fs = std::filesystem;

const fs::path sample = "samples/drape";  // relative to the source dir, as the reports name it
const fs::path expected_dir = "samples/drape-expected";

struct ExpectedPair {
  int32_t a, b;
  std::string kind;
  int32_t poly_a, poly_b;
};

class DrapeExpected : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = source_dir();
    ASSERT_TRUE(fs::is_directory(root_ / sample)) << (root_ / sample) << " is missing";
    pairs_text_ = read_text(root_ / expected_dir / "pairs.csv");
    frames_text_ = read_text(root_ / expected_dir / "frames.csv");
    const auto rows = parse_csv(pairs_text_);
    ASSERT_FALSE(rows.empty());
    ASSERT_EQ(rows[0],
              (std::vector<std::string>{"frame", "face_a", "face_b", "kind", "poly_a", "poly_b"}));
    for (size_t i = 1; i < rows.size(); ++i) {
      ASSERT_EQ(rows[i].size(), 6u) << "pairs.csv row " << i;
      pairs_[std::stoll(rows[i][0])].push_back({std::stoi(rows[i][1]), std::stoi(rows[i][2]),
                                                rows[i][3], std::stoi(rows[i][4]),
                                                std::stoi(rows[i][5])});
      any_crossing_ = any_crossing_ || rows[i][3] == "crossing";
    }
  }

  fs::path root_;
  std::string pairs_text_;
  std::string frames_text_;
  std::map<int64_t, std::vector<ExpectedPair>> pairs_;
  bool any_crossing_ = false;
};

/// The expected frames.csv leaves out `seconds` (a time); compare snag's without it.
std::string without_seconds(const std::string& csv) {
  const auto rows = parse_csv(csv);
  const auto& header = rows.at(0);
  const size_t skip =
      static_cast<size_t>(std::find(header.begin(), header.end(), "seconds") - header.begin());
  std::string out;
  for (const auto& row : rows) {
    for (size_t i = 0; i < row.size(); ++i) {
      if (i == skip) continue;
      if (!out.empty() && out.back() != '\n') out += ",";
      out += row[i];
    }
    out += "\n";
  }
  return out;
}

TEST_F(DrapeExpected, PairsAgreeWithCgal) {
  const auto frames = seq::resolve_sequence((root_ / sample).string());
  ASSERT_GE(frames.size(), 2u);
  auto resolver = validators::make_cgal_resolver();
  int64_t checked_pairs = 0;
  for (const seq::Frame& frame : frames) {
    SCOPED_TRACE(frame.path.string());
    const mesh::Mesh mesh = io::read_mesh(frame.path);
    const auto reference = validators::cgal_self_intersections(mesh.positions, mesh.triangles);
    const auto it = pairs_.find(frame.number);
    const std::vector<ExpectedPair> expected =
        it == pairs_.end() ? std::vector<ExpectedPair>{} : it->second;

    std::vector<std::pair<int32_t, int32_t>> ids;
    for (const auto& p : expected) ids.emplace_back(p.a, p.b);
    ASSERT_EQ(ids, reference) << "samples/drape-expected/pairs.csv disagrees with CGAL on frame "
                              << frame.number;

    // Polygon ids are the file's faces; OBJ triangles here are the file's own faces.
    std::vector<detect::FacePair> face_pairs;
    for (const auto& p : expected) {
      EXPECT_EQ(p.poly_a, mesh.source_polygon.at(p.a));
      EXPECT_EQ(p.poly_b, mesh.source_polygon.at(p.b));
      face_pairs.push_back({p.a, p.b, detect::PairKind::crossing});
    }
    // Kinds decided with CGAL's exact predicates alone (no double filter in the way).
    const detect::Topology topology =
        detect::make_topology(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
    std::vector<detect::PairKind> kinds(face_pairs.size());
    resolver->pair_kinds({mesh.positions, &topology}, face_pairs, kinds);
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_EQ(expected[i].kind, detect::to_string(kinds[i]))
          << "frame " << frame.number << " pair (" << expected[i].a << ", " << expected[i].b << ")";
    checked_pairs += static_cast<int64_t>(expected.size());
  }
  EXPECT_GT(checked_pairs, 0) << "the sample is meant to fold through itself";
  EXPECT_TRUE(any_crossing_);
}

TEST_F(DrapeExpected, FramesCsvAgreesWithPairsCsv) {
  const auto rows = parse_csv(frames_text_);
  ASSERT_EQ(rows.at(0),
            (std::vector<std::string>{"frame", "file", "triangles", "pairs", "crossing", "touching",
                                      "degenerate", "uncertain", "rebuilt", "topology_changed"}));
  const auto frames = seq::resolve_sequence((root_ / sample).string());
  ASSERT_EQ(rows.size(), frames.size() + 1);
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& row = rows[i + 1];
    ASSERT_EQ(row.size(), 10u);
    EXPECT_EQ(std::stoll(row[0]), frames[i].number);
    EXPECT_EQ(row[1], (sample / frames[i].path.filename()).string());
    const auto it = pairs_.find(frames[i].number);
    const auto& p = it == pairs_.end() ? std::vector<ExpectedPair>{} : it->second;
    const auto crossing = std::count_if(p.begin(), p.end(),
                                        [](const ExpectedPair& e) { return e.kind == "crossing"; });
    EXPECT_EQ(std::stoll(row[3]), static_cast<int64_t>(p.size())) << row[0];
    EXPECT_EQ(std::stoll(row[4]), crossing) << row[0];
    EXPECT_EQ(std::stoll(row[5]), static_cast<int64_t>(p.size()) - crossing) << row[0];
  }
}

TEST_F(DrapeExpected, SnagReportsMatch) {
  TempDir tmp;
  const RunResult r =
      run_snag({"check", sample.string(), "--out", (tmp.path() / "out").string()}, root_);
  ASSERT_EQ(r.status, any_crossing_ ? 1 : 0) << r.err;
  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"), pairs_text_);
  EXPECT_EQ(without_seconds(read_text(tmp.path() / "out" / "frames.csv")), frames_text_);
}

TEST_F(DrapeExpected, SamePairsWithOneThreadAndEveryRebuildPolicy) {
  TempDir tmp;
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--threads", "1", "--rebuild", "always"},
        {"--threads", "2", "--rebuild", "never"}}) {
    std::vector<std::string> args = {"check", sample.string(), "--quiet", "--out",
                                     (tmp.path() / "out").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = run_snag(args, root_);
    ASSERT_EQ(r.status, any_crossing_ ? 1 : 0) << r.err;
    EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"), pairs_text_)
        << extra[1] << " " << extra[3];
  }
}

// samples/drape-scene.json ------------------------------------------------------------------

const fs::path scene_file = "samples/drape-scene.json";
const fs::path scene_expected_dir = "samples/drape-scene-expected";
const fs::path body_file = "samples/drape_body.obj";

/// One row of a scene's pairs.csv.
struct ScenePair {
  int32_t a, b;
  std::string kind;
  int32_t poly_a, poly_b;
  std::string object_a, object_b;
};

class DrapeSceneExpected : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = source_dir();
    ASSERT_TRUE(fs::is_regular_file(root_ / scene_file)) << (root_ / scene_file) << " is missing";
    pairs_text_ = read_text(root_ / scene_expected_dir / "pairs.csv");
    frames_text_ = read_text(root_ / scene_expected_dir / "frames.csv");
    const auto rows = parse_csv(pairs_text_);
    ASSERT_FALSE(rows.empty());
    ASSERT_EQ(rows[0], (std::vector<std::string>{"frame", "face_a", "face_b", "kind", "poly_a",
                                                 "poly_b", "object_a", "object_b"}));
    for (size_t i = 1; i < rows.size(); ++i) {
      ASSERT_EQ(rows[i].size(), 8u) << "pairs.csv row " << i;
      pairs_[std::stoll(rows[i][0])].push_back({std::stoi(rows[i][1]), std::stoi(rows[i][2]),
                                                rows[i][3], std::stoi(rows[i][4]),
                                                std::stoi(rows[i][5]), rows[i][6], rows[i][7]});
      any_crossing_ = any_crossing_ || rows[i][3] == "crossing";
    }
    frames_ = seq::resolve_sequence((root_ / sample).string());
  }

  std::vector<ScenePair> pairs_of(int64_t frame) const {
    const auto it = pairs_.find(frame);
    return it == pairs_.end() ? std::vector<ScenePair>{} : it->second;
  }

  fs::path root_;
  std::string pairs_text_;
  std::string frames_text_;
  std::map<int64_t, std::vector<ScenePair>> pairs_;
  std::vector<seq::Frame> frames_;
  bool any_crossing_ = false;
};

/// Twice the signed solid angle `triangle` spans seen from `p`, over 4 pi: summed over a closed
/// outward surface, 1 inside and 0 outside (Van Oosterom and Strackee).
double winding_number(const std::vector<geom::Vec3d>& positions,
                      const std::vector<geom::Tri>& triangles, geom::Vec3d p) {
  double sum = 0;
  for (const geom::Tri& t : triangles) {
    const geom::Vec3d a = positions[t.v[0]] - p, b = positions[t.v[1]] - p,
                      c = positions[t.v[2]] - p;
    const double la = std::sqrt(dot(a, a)), lb = std::sqrt(dot(b, b)), lc = std::sqrt(dot(c, c));
    sum += 2 * std::atan2(dot(a, cross(b, c)),
                          la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb);
  }
  return sum / (4 * std::numbers::pi);
}

/// The distance from p to the closed triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double distance_to_triangle(geom::Vec3d p, geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) {
  const auto length = [](geom::Vec3d v) { return std::sqrt(dot(v, v)); };
  const geom::Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return length(p - a);
  const geom::Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return length(p - (a + (d1 / (d1 - d3)) * ab));
  const geom::Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + (d2 / (d2 - d6)) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return length(p - (b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)));
  const double denom = 1 / (va + vb + vc);
  return length(p - (a + (vb * denom) * ab + (vc * denom) * ac));
}

TEST_F(DrapeSceneExpected, PairsAgreeWithCgal) {
  const mesh::Mesh body = io::read_mesh(root_ / body_file);
  ASSERT_EQ(body.triangles.size(), 960u);
  int64_t cross_pairs = 0, self_pairs = 0;
  for (const seq::Frame& frame : frames_) {
    SCOPED_TRACE(frame.path.string());
    const mesh::Mesh cloth = io::read_mesh(frame.path);
    std::vector<std::pair<int32_t, int32_t>> self, cross;
    for (const ScenePair& p : pairs_of(frame.number)) {
      if (p.object_a == "drape" && p.object_b == "drape") {
        self.emplace_back(p.a, p.b);
      } else {
        ASSERT_EQ(p.object_a, "drape");  // the cloth comes first in the scene
        ASSERT_EQ(p.object_b, "body");
        cross.emplace_back(p.a, p.b);
      }
      EXPECT_EQ(p.poly_a, p.a);  // both files have triangles only
      EXPECT_EQ(p.poly_b, p.b);
    }
    EXPECT_EQ(self, validators::cgal_self_intersections(cloth.positions, cloth.triangles))
        << "drape/drape self pairs disagree with CGAL on frame " << frame.number;
    EXPECT_EQ(cross, validators::cgal_pairs_between(cloth.positions, cloth.triangles,
                                                    body.positions, body.triangles))
        << "drape/body pairs disagree with CGAL on frame " << frame.number;

    // Kinds from CGAL alone, the two meshes' vertices laid end to end (no shared ids).
    std::vector<geom::Vec3d> both = cloth.positions;
    both.insert(both.end(), body.positions.begin(), body.positions.end());
    const auto offset = static_cast<int32_t>(cloth.positions.size());
    for (const ScenePair& p : pairs_of(frame.number)) {
      geom::Tri g = p.object_b == "body" ? body.triangles.at(p.b) : cloth.triangles.at(p.b);
      if (p.object_b == "body")
        for (int32_t& v : g.v) v += offset;
      EXPECT_EQ(p.kind,
                detect::to_string(validators::cgal_pair_kind(both, cloth.triangles.at(p.a), g)))
          << p.object_a << " " << p.a << ", " << p.object_b << " " << p.b;
    }
    self_pairs += static_cast<int64_t>(self.size());
    cross_pairs += static_cast<int64_t>(cross.size());
  }
  EXPECT_GT(cross_pairs, 0) << "the drape is meant to go into the body";
  EXPECT_GT(self_pairs, 0) << "the drape is meant to fold through itself";
}

TEST_F(DrapeSceneExpected, FramesCsvAgreesWithPairsAndPenetration) {
  const mesh::Mesh body = io::read_mesh(root_ / body_file);
  const auto rows = parse_csv(frames_text_);
  ASSERT_EQ(rows.at(0),
            (std::vector<std::string>{"frame", "file", "triangles", "pairs", "crossing", "touching",
                                      "degenerate", "uncertain", "rebuilt", "topology_changed",
                                      "reused_pairs", "inside_vertices", "max_depth"}));
  ASSERT_EQ(rows.size(), frames_.size() + 1);
  int64_t inside_somewhere = 0;
  for (size_t i = 0; i < frames_.size(); ++i) {
    SCOPED_TRACE(frames_[i].path.string());
    const auto& row = rows[i + 1];
    ASSERT_EQ(row.size(), 13u);
    EXPECT_EQ(std::stoll(row[0]), frames_[i].number);
    EXPECT_EQ(row[1], (sample / frames_[i].path.filename()).string());
    EXPECT_EQ(row[2], "1760");  // 800 cloth and 960 body triangles
    const auto p = pairs_of(frames_[i].number);
    const auto crossing =
        std::count_if(p.begin(), p.end(), [](const ScenePair& e) { return e.kind == "crossing"; });
    EXPECT_EQ(std::stoll(row[3]), static_cast<int64_t>(p.size()));
    EXPECT_EQ(std::stoll(row[4]), crossing);
    EXPECT_EQ(std::stoll(row[5]), static_cast<int64_t>(p.size()) - crossing);
    EXPECT_EQ(row[10], "0");  // the cloth moves in every frame

    // Inside the body: winding number 1 (0 outside; nothing lies near the surface here, so
    // 0.5 splits them); depth: the distance to the nearest body triangle.
    const mesh::Mesh cloth = io::read_mesh(frames_[i].path);
    int64_t inside = 0;
    double max_depth = 0;
    for (const geom::Vec3d& v : cloth.positions) {
      const double w = winding_number(body.positions, body.triangles, v);
      ASSERT_TRUE(std::abs(w) < 1e-6 || std::abs(w - 1) < 1e-6) << "winding number " << w;
      if (w < 0.5) continue;
      double depth = INFINITY;
      for (const geom::Tri& t : body.triangles)
        depth =
            std::min(depth, distance_to_triangle(v, body.positions[t.v[0]], body.positions[t.v[1]],
                                                 body.positions[t.v[2]]));
      ++inside;
      max_depth = std::max(max_depth, depth);
    }
    EXPECT_EQ(std::stoll(row[11]), inside);
    EXPECT_NEAR(std::stod(row[12]), max_depth, 5.1e-7);  // printed with 6 decimals
    inside_somewhere += inside;
  }
  EXPECT_GT(inside_somewhere, 0) << "the drape is meant to go into the body";
}

TEST_F(DrapeSceneExpected, SnagReportsMatch) {
  TempDir tmp;
  const RunResult r = run_snag(
      {"check", "--scene", scene_file.string(), "--quiet", "--out", (tmp.path() / "out").string()},
      root_);
  ASSERT_EQ(r.status, any_crossing_ ? 1 : 0) << r.err;
  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"), pairs_text_);
  EXPECT_EQ(without_seconds(read_text(tmp.path() / "out" / "frames.csv")), frames_text_);

  // report.json: the body is still, read and built once, and closed; its penetration records
  // are frames.csv's.
  const auto j = nlohmann::json::parse(read_text(tmp.path() / "out" / "report.json"));
  const auto& objects = j.at("inputs").at("objects");
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].at("name"), "drape");
  EXPECT_EQ(objects[0].at("sequence"), "samples/drape/drape.%04d.obj");  // resolved
  EXPECT_EQ(objects[1].at("name"), "body");
  EXPECT_EQ(objects[1].at("sequence"), body_file.string());
  EXPECT_EQ(objects[1].at("still"), true);
  EXPECT_EQ(objects[1].at("closed"), "closed");
  const auto rows = parse_csv(frames_text_);
  ASSERT_EQ(j.at("frames").size(), frames_.size());
  for (size_t i = 0; i < frames_.size(); ++i) {
    const auto& f = j.at("frames")[i];
    EXPECT_EQ(f.at("objects")[1].at("rebuilt"), i == 0) << f.at("frame");
    if (i > 0) EXPECT_EQ(f.at("objects")[1].at("moved"), false) << f.at("frame");
    ASSERT_EQ(f.at("penetration").size(), 1u);
    EXPECT_EQ(f.at("penetration")[0].at("inside"), std::stoll(rows[i + 1][11]));
  }
}

TEST_F(DrapeSceneExpected, ObstacleFlagGivesTheScenePairs) {
  // `snag check CLOTH --obstacle BODY` is the same scene, its objects named cloth and
  // drape_body (after the file).
  TempDir tmp;
  const RunResult r = run_snag({"check", sample.string(), "--obstacle", body_file.string(),
                                "--quiet", "--out", (tmp.path() / "out").string()},
                               root_);
  ASSERT_EQ(r.status, any_crossing_ ? 1 : 0) << r.err;
  std::string expected;
  for (const auto& row : parse_csv(pairs_text_)) {
    for (size_t i = 0; i < row.size(); ++i) {
      std::string field = row[i];
      if (i >= 6 && field == "drape") field = "cloth";
      if (i >= 6 && field == "body") field = "drape_body";
      expected += (i ? "," : "") + field;
    }
    expected += "\n";
  }
  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"), expected);
}

}  // namespace
}  // namespace snag::test
