// `snag bench cpu` end to end on the drape sample (no generated cloth, no data folder): every
// frame's pairs are CGAL's, on the rebuilding and the refitting checker alike (the bench fails
// otherwise), and the table has the sample's row.
#include <cstdlib>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cli/run_snag.h"
#include "test_paths.h"

namespace snag::test {
namespace {

TEST(CliBench, CpuFindsCgalsPairsInEveryFrameOfTheDrape) {
  TempDir tmp;
  const std::filesystem::path no_data = tmp.path() / "no-data";
  std::filesystem::create_directories(no_data);
  ::setenv("SNAG_DATA_DIR", no_data.c_str(), 1);  // the cloth-ball case is left out
  // Two passes over the 12 frames, the last one frame 12 (564 pairs by CGAL's count too).
  const RunResult r = run_snag({"bench", "cpu", "--sizes", "0", "--threads", "2", "--input",
                                (source_dir() / "samples/drape").string(), "--warmup", "12",
                                "--frames", "12"},
                               tmp.path());
  ::unsetenv("SNAG_DATA_DIR");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line, row;
  while (std::getline(lines, line))
    if (line.rfind("drape", 0) == 0) row = line;
  ASSERT_FALSE(row.empty()) << r.out;
  std::istringstream fields(row);
  std::string name, field, pairs, same;
  fields >> name;
  int columns = 1;
  while (fields >> field) {
    pairs = same;
    same = field;
    ++columns;
  }
  EXPECT_EQ(columns, 14) << row;  // case, triangles, frames, ..., CGAL/snag, pairs, same
  EXPECT_EQ(same, "yes") << row;
  EXPECT_GT(std::stol(pairs), 0) << row;
}

}  // namespace
}  // namespace snag::test
