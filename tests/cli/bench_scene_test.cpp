// `snag bench scene` end to end on a small generated cloth and sphere: every table is printed
// with every scene on every backend it ran on (the GPU's rows, or a note that they were
// skipped), the still obstacle is never refit, the frozen frame's checks are all reused, the
// self check nobody asked for appears only where it was asked for, and the command's options
// are those of its man page section. Structure only: no timing is compared, so nothing flakes.
#include <algorithm>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/run_snag.h"
#include "test_paths.h"

namespace snag::test {
namespace {

constexpr int kFrames = 4;

/// `line` with runs of spaces made one.
std::string collapsed(const std::string& line) {
  std::string out;
  for (char c : line)
    if (c != ' ' || (!out.empty() && out.back() != ' ')) out.push_back(c);
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

/// The lines of the table whose header starts with `header` (spaces collapsed), up to the next
/// blank line or the end, spaces collapsed.
std::vector<std::string> table(const std::string& text, const std::string& header) {
  std::istringstream lines(text);
  std::vector<std::string> rows;
  bool inside = false;
  for (std::string line; std::getline(lines, line);) {
    const std::string c = collapsed(line);
    if (!inside) {
      inside = c.rfind(header, 0) == 0;
      continue;
    }
    if (c.empty()) break;
    rows.push_back(c);
  }
  EXPECT_TRUE(inside) << "no table headed '" << header << "' in:\n" << text;
  return rows;
}

/// The words after `prefix` of the row of `rows` that starts with it (table_row over the rows).
std::vector<std::string> words_after(const std::vector<std::string>& rows,
                                     const std::string& prefix) {
  std::string text;
  for (const std::string& r : rows) text += r + "\n";
  return table_row(text, prefix + " ");
}

size_t rows_starting(const std::vector<std::string>& rows, const std::string& prefix) {
  return static_cast<size_t>(std::count_if(rows.begin(), rows.end(), [&](const std::string& r) {
    return r.rfind(prefix + " ", 0) == 0;
  }));
}

std::string fraction(int a, int b) {
  return std::to_string(a) + "/" + std::to_string(b);
}

TEST(CliBench, SceneTablesShowWhatEachSceneChecks) {
  TempDir tmp;
  const RunResult r =
      run_snag({"bench", "scene", "--size", "2000", "--obstacle-size", "2000", "--frames",
                std::to_string(kFrames), "--warmup", "1", "--threads", "2"},
               tmp.path());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> scenes = table(r.out, "backend scene objects set first check");
  const std::vector<std::string> objects = table(r.out, "backend scene object triangles");
  const std::vector<std::string> checks = table(r.out, "backend scene check ms");

  std::vector<std::string> backends = {"cpu"};
  if (rows_starting(scenes, "cuda cloth alone") == 1)
    backends.push_back("cuda");
  else
    EXPECT_EQ(rows_starting(scenes, "cuda skipped:"), 1u) << r.out;

  for (const std::string& b : backends) {
    SCOPED_TRACE(b);
    // Main table: objects, set, first, check, read, snag check, pairs, reused (checks of the
    // timed frames whose pairs were kept).
    const std::vector<std::pair<std::string, int>> expected = {{"cloth alone", 1},
                                                               {"still obstacle", 2},
                                                               {"moving obstacle", 2},
                                                               {"obstacle self too", 3},
                                                               {"frozen frame", 2}};
    std::string cloth_pairs;
    for (const auto& [scene, check_count] : expected) {
      SCOPED_TRACE(scene);
      const std::vector<std::string> w = words_after(scenes, b + " " + scene);
      ASSERT_EQ(w.size(), 8u);
      EXPECT_EQ(w[0], scene == "cloth alone" ? "1" : "2");
      for (size_t i = 1; i <= 5; ++i) EXPECT_GE(std::stod(w[i]), 0.0) << "column " << i;
      EXPECT_GT(std::stoll(w[6]), 0);  // the folded cloth goes through itself
      const int runs = check_count * kFrames;
      EXPECT_EQ(w[7], fraction(scene == "frozen frame" ? runs : 0, runs));
      if (scene == "cloth alone") cloth_pairs = w[6];
      // One row per check, and only the checks the scene asks for.
      EXPECT_EQ(rows_starting(checks, b + " " + scene), static_cast<size_t>(check_count));
    }
    // A row's pairs are its checks' pairs; the cloth's own pairs do not depend on what is
    // beside it (the same cloth frames in every scene but the frozen one).
    for (const auto& [scene, check_count] : expected) {
      int64_t sum = 0;
      for (const std::string& row : checks)
        if (row.rfind(b + " " + scene + " ", 0) == 0)
          sum += std::stoll(words_after({row}, b + " " + scene).end()[-2]);
      EXPECT_EQ(std::to_string(sum), words_after(scenes, b + " " + scene)[6]) << scene;
      if (scene != "frozen frame")
        EXPECT_EQ(words_after(checks, b + " " + scene + " cloth self")[1], cloth_pairs) << scene;
    }

    // Per object: triangles, still, build, refit, moved, rebuilt.
    const std::string all = fraction(kFrames, kFrames), none = fraction(0, kFrames);
    const std::vector<std::string> still = words_after(objects, b + " still obstacle obstacle");
    ASSERT_EQ(still.size(), 6u);
    EXPECT_EQ(still[1], "yes");
    EXPECT_EQ(std::stod(still[3]), 0.0);  // never refit
    EXPECT_EQ(still[4], none);
    EXPECT_EQ(words_after(objects, b + " still obstacle cloth")[4], all);
    const std::vector<std::string> moving = words_after(objects, b + " moving obstacle obstacle");
    ASSERT_EQ(moving.size(), 6u);
    EXPECT_EQ(moving[1], "no");
    EXPECT_EQ(moving[4], all);
    for (const char* object : {"cloth", "obstacle"}) {
      const std::vector<std::string> frozen = words_after(objects, b + " frozen frame " + object);
      ASSERT_EQ(frozen.size(), 6u) << object;
      EXPECT_EQ(std::stod(frozen[3]), 0.0) << object;
      EXPECT_EQ(frozen[4], none) << object;
    }

    // Per check: ms, pairs, reused.
    EXPECT_EQ(words_after(checks, b + " obstacle self too obstacle self").size(), 3u);
    EXPECT_EQ(rows_starting(checks, b + " moving obstacle obstacle self"), 0u);
    for (const char* check : {"cloth self", "cloth x obstacle"}) {
      const std::vector<std::string> frozen = words_after(checks, b + " frozen frame " + check);
      ASSERT_EQ(frozen.size(), 3u) << check;
      EXPECT_EQ(std::stod(frozen[0]), 0.0) << check;  // not run: its pairs were kept
      EXPECT_EQ(frozen[2], all) << check;
      EXPECT_EQ(words_after(checks, b + " moving obstacle " + check)[2], none) << check;
    }
  }
}

TEST(CliBench, SceneOptionsAreThoseOfTheManPage) {
  TempDir tmp;
  const RunResult help = run_snag({"bench", "scene", "--help"}, tmp.path());
  ASSERT_EQ(help.status, 0);
  const std::string man = read_text(source_dir() / "man" / "snag.1");
  const size_t start = man.find(".SS \"snag bench scene");
  ASSERT_NE(start, std::string::npos) << "man/snag.1 has no snag bench scene section";
  const size_t end = man.find("\n.S", start + 1);
  const std::string section = std::regex_replace(
      man.substr(start, end == std::string::npos ? std::string::npos : end - start),
      std::regex(R"(\\-)"), "-");
  auto options = [](const std::string& text) {
    std::set<std::string> found;
    const std::regex option(R"((^|[\s,\[])(--[a-z][a-z-]*|-[a-zA-Z])\b)");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), option);
         it != std::sregex_iterator(); ++it)
      if ((*it)[2] != "-h" && (*it)[2] != "--help") found.insert((*it)[2]);
    return found;
  };
  EXPECT_EQ(options(help.out), options(section));
  // And in the synopsis.
  EXPECT_NE(man.find(".B snag bench scene\n"), std::string::npos);
}

}  // namespace
}  // namespace snag::test
