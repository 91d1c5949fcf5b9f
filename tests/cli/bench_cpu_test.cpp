// `snag bench cpu` end to end on the drape sample (no generated cloth, no data folder): every
// frame's pairs are CGAL's, on the rebuilding and the refitting checker alike (the bench fails
// otherwise), and the table has the sample's row.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/run_snag.h"
#include "test_paths.h"

namespace snag::test {
namespace {

TEST(CliBench, CpuFindsCgalsPairsInEveryFrameOfTheDrape) {
  TempDir tmp;
  // Two passes over the 12 frames, the last one frame 12 (564 pairs by CGAL's count too).
  const RunResult r = run_snag_without_data(
      {"bench", "cpu", "--sizes", "0", "--threads", "2", "--input",
       (source_dir() / "samples/drape").string(), "--warmup", "12", "--frames", "12"},
      tmp.path());
  ASSERT_EQ(r.status, 0) << r.err;
  // triangles, frames, read, MB/s, build, refit, traverse, exact, total, CGAL, CGAL/snag,
  // pairs, same
  const std::vector<std::string> row = table_row(r.out, "drape ");
  ASSERT_EQ(row.size(), 13u) << r.out;
  EXPECT_EQ(row[12], "yes");
  EXPECT_GT(std::stol(row[11]), 0);
}

}  // namespace
}  // namespace snag::test
