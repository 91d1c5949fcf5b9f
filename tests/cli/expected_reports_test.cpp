// The committed expected reports of samples/drape: snag's reports must match them, and they
// must match CGAL's self_intersections, frame by frame, so they are not merely a recording of
// snag's own output.
#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace snag::test
