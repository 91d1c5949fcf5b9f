// `snag bench io` end to end on a small generated cloth: every table is printed, every reader
// reads every case it can at a positive rate, and the whole-sequence run found the same pairs
// as checking from memory (the bench fails otherwise).
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/run_snag.h"

namespace snag::test {
namespace {

/// The whitespace-separated words of the `nth` line (from 0) of `text` that starts with
/// `prefix`.
std::vector<std::string> row(const std::string& text, const std::string& prefix, int nth = 0) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) != 0 || nth-- > 0) continue;
    std::istringstream in(line.substr(prefix.size()));
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    return words;
  }
  ADD_FAILURE() << "no line starting '" << prefix << "' in:\n" << text;
  return {};
}

TEST(CliBench, IoReadsEveryFormatAndChecksTheSequence) {
  TempDir tmp;
  const std::filesystem::path no_data = tmp.path() / "no-data";
  std::filesystem::create_directories(no_data);
  ::setenv("SNAG_DATA_DIR", no_data.c_str(), 1);  // the cloth-ball case is left out
  const RunResult r = run_snag({"bench", "io", "--size", "800", "--frames", "8", "--passes", "1",
                                "--memory-frames", "2,8", "--threads", "2"},
                               tmp.path());
  ::unsetenv("SNAG_DATA_DIR");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* format : {"OBJ", "PLY binary", "PLY ascii"}) {
    const std::vector<std::string> rates = row(r.out, std::string("cloth 800 ") + format);
    ASSERT_EQ(rates.size(), 7u) << format;  // frames, MB/frame, then five readers
    EXPECT_EQ(rates[0], "8") << format;
    for (size_t i = 2; i < rates.size(); ++i) {
      if (rates[i] == "-") {
        EXPECT_NE(std::string(format), "OBJ");  // only tinyobjloader skips, and only PLY
        continue;
      }
      EXPECT_GT(std::stod(rates[i]), 0) << format << " reader " << i - 2;
    }
  }
  const std::vector<std::string> cpu = row(r.out, "cpu ");
  ASSERT_EQ(cpu.size(), 8u);
  EXPECT_EQ(cpu[0], "1");           // readers: one per 16 threads, at least one
  EXPECT_GT(std::stod(cpu[3]), 0);  // snag check, seconds
  // Where the loop's time went: five shares, none negative, adding up to no more than the loop.
  const std::vector<std::string> loop = row(r.out, "cpu ", 1);
  ASSERT_EQ(loop.size(), 6u);
  double shares = 0;
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_GE(std::stod(loop[i]), 0) << i;
    shares += std::stod(loop[i]);
  }
  EXPECT_GT(std::stod(loop[2]), 0);               // checking
  EXPECT_EQ(loop[5], cpu[3]);                     // the loop is snag check's time
  EXPECT_LE(shares, std::stod(loop[5]) + 0.005);  // three decimals each, rounded
  for (const char* frames : {"       2 ", "       8 "})
    EXPECT_EQ(row(r.out, frames).size(), 3u) << frames;
}

}  // namespace
}  // namespace snag::test
