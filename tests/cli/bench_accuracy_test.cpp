// `snag bench accuracy` end to end on the hard-case corpus (no generated cloth, no data
// folder): the table is written, the exact modes and CGAL score no error against the exact
// answer, and the methods that guess are caught guessing, so the scoring is not vacuous.
#include <map>
#include <string>

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
  for (const char* exact : {"snag cpu --exact uncertain", "snag cpu --exact all",
                            "CGAL self_intersections"}) {
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

}  // namespace
}  // namespace snag::test
