// `snag bench accuracy` end to end on the hard-case corpus (no generated cloth, no data
// folder): the table is written, the exact modes and CGAL score no error against the exact
// answer, and the methods that guess are caught guessing, so the scoring is not vacuous.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/run_snag.h"
#include "test_paths.h"

namespace snag::test {
namespace {

TEST(CliBench, AccuracyScoresTheHardCasesAgainstTheExactAnswer) {
  TempDir tmp;
  const RunResult r = run_snag_without_data(
      {"bench", "accuracy", "--sizes", "0", "--threads", "2", "--hard",
       (source_dir() / "samples/hard").string(), "-o", (tmp.path() / "acc").string()},
      tmp.path());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(read_text(tmp.path() / "acc/accuracy.md").empty());
  const auto rows = parse_csv(read_text(tmp.path() / "acc/accuracy.csv"));
  ASSERT_GE(rows.size(), 6u);
  ASSERT_EQ(rows[0][3], "method");
  std::map<std::string, std::vector<std::string>> by_method;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 10u);
    EXPECT_EQ(rows[i][0].rfind("hard cases", 0), 0u) << rows[i][0];
    by_method[rows[i][3]] = rows[i];
  }
  auto wrong = [&](const std::string& method) {
    const auto& row = by_method.at(method);
    const long kinds = row[8] == "n/a" ? 0 : std::stol(row[8]);
    return std::stol(row[6]) + std::stol(row[7]) + kinds;
  };
  for (const char* exact :
       {"snag cpu --exact uncertain", "snag cpu --exact all", "CGAL self_intersections"}) {
    EXPECT_EQ(wrong(exact), 0) << exact;
    EXPECT_EQ(by_method.at(exact)[9], "0") << exact;
  }
  EXPECT_EQ(by_method.at("CGAL self_intersections")[8], "n/a");
  // The corpus is built to defeat guesses: --exact off decides signs outside its bound (and
  // says how many), and the plain floating-point test gets pairs or kinds wrong.
  EXPECT_GT(std::stol(by_method.at("snag cpu --exact off")[9]), 0);
  EXPECT_GT(wrong("float tri-tri (no filter)"), 0);
  EXPECT_EQ(by_method.at("snag cpu --exact uncertain")[5], by_method.at("snag cpu --exact all")[5]);
}

// A --data folder holding part of the shared data (here one of ipc-toolkit's files) scores what
// it holds; one holding none of it is a usage error, as a mistyped path would be.
TEST(CliBench, AccuracyTakesWhatAPartialDataFolderHolds) {
  TempDir tmp;
  const std::filesystem::path data = tmp.path() / "data";
  std::filesystem::create_directories(data / "ipc-toolkit");
  write_text(data / "ipc-toolkit" / "two-cubes-far.ply",
             "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
             "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n5 5 5\n6 5 5\n5 6 5\n3 0 1 2\n3 3 4 5\n");
  const auto args_with = [&](const std::string& data_dir) {
    return std::vector<std::string>{"bench",  "accuracy", "--sizes", "0",  "--data",
                                    data_dir, "--frames", "1",       "-o", "acc"};
  };
  const RunResult r = run_snag(args_with(data.string()), tmp.path());
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<std::string, int> rows_per_input;
  for (const auto& row : parse_csv(read_text(tmp.path() / "acc/accuracy.csv")))
    ++rows_per_input[row[0].substr(0, row[0].find(" ("))];
  EXPECT_GT(rows_per_input["ipc two-cubes-far.ply"], 0);
  EXPECT_GT(rows_per_input["hard cases"], 0);
  EXPECT_EQ(rows_per_input.size(), 3u);  // and the header
  EXPECT_NE(r.err.find("the cloth-ball case is left out"), std::string::npos) << r.err;

  std::filesystem::create_directories(tmp.path() / "empty");
  const RunResult empty = run_snag(args_with((tmp.path() / "empty").string()), tmp.path());
  EXPECT_EQ(empty.status, 2) << empty.err;
  EXPECT_NE(empty.err.find("none of its cases is in it"), std::string::npos) << empty.err;
  // An empty hard-case corpus too (it crashed the bench).
  std::vector<std::string> no_hard_cases = args_with(data.string());
  no_hard_cases.insert(no_hard_cases.end(), {"--hard", (tmp.path() / "empty").string()});
  const RunResult hard = run_snag(no_hard_cases, tmp.path());
  EXPECT_EQ(hard.status, 2) << hard.err;
  EXPECT_NE(hard.err.find("no cases in it"), std::string::npos) << hard.err;
}

}  // namespace
}  // namespace snag::test
