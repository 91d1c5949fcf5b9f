// Sequence resolution (files, directories, frame tokens, globs) and --frames selections.
#include "snag/seq/sequence.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "snag/error.h"

namespace snag::seq {
namespace {
namespace fs = std::filesystem;

/// A fresh directory of empty files for one test, removed afterwards.
class SequenceDir : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / ("snag_seq_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void touch(std::initializer_list<std::string> names) {
    for (const std::string& n : names) std::ofstream(dir_ / n) << "v 0 0 0\n";
  }
  std::string at(const std::string& name) const { return (dir_ / name).string(); }
  /// The InputError's message for resolving `spec` in the directory, or "resolved".
  std::string message(const std::string& spec) const {
    try {
      resolve_sequence(at(spec));
    } catch (const InputError& e) {
      return e.what();
    }
    return "resolved";
  }

  /// (number, file name) pairs of a resolved sequence.
  static std::vector<std::pair<int64_t, std::string>> names(const std::vector<Frame>& frames) {
    std::vector<std::pair<int64_t, std::string>> out;
    for (const Frame& f : frames) out.emplace_back(f.number, f.path.filename().string());
    return out;
  }
  using Names = std::vector<std::pair<int64_t, std::string>>;

  fs::path dir_;
};

TEST_F(SequenceDir, SingleFileTakesTheDigitsOfItsName) {
  touch({"dress.0042.obj", "body.obj"});
  EXPECT_EQ(names(resolve_sequence(at("dress.0042.obj"))), (Names{{42, "dress.0042.obj"}}));
  EXPECT_EQ(names(resolve_sequence(at("body.obj"))), (Names{{0, "body.obj"}}));
  EXPECT_EQ(resolve_sequence(at("body.obj"))[0].path, dir_ / "body.obj");
  // Digits past 64 bits (a timestamp to the microsecond) label no frame but are no reason to
  // refuse the file (found by fuzzing): frame 0. In a directory they are an error (below).
  touch({"scan_20240803123456789012345.obj"});
  EXPECT_EQ(names(resolve_sequence(at("scan_20240803123456789012345.obj"))),
            (Names{{0, "scan_20240803123456789012345.obj"}}));
  try {
    resolve_sequence(dir_.string());
    ADD_FAILURE() << "a directory with that name resolved";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit in 64 bits"), std::string::npos) << e.what();
  }
}

TEST_F(SequenceDir, DirectoryListsObjAndPlyFilesInNumericOrder) {
  touch({"f100.obj", "f2.obj", "f10.OBJ", "f3.ply", "notes.txt", "f7.obj.bak", "cache_v2_f1.Ply"});
  fs::create_directories(dir_ / "sub.obj");
  EXPECT_EQ(names(resolve_sequence(dir_.string())), (Names{{1, "cache_v2_f1.Ply"},
                                                           {2, "f2.obj"},
                                                           {3, "f3.ply"},
                                                           {10, "f10.OBJ"},
                                                           {100, "f100.obj"}}));
}

TEST_F(SequenceDir, DirectoryWithTwoFilesOfOneFrameIsAnError) {
  touch({"cloth.0001.obj", "body.0001.obj"});
  try {
    resolve_sequence(dir_.string());
    FAIL() << "accepted two files for frame 1";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), dir_.string());
    EXPECT_NE(std::string(e.what()).find("two files have frame number 1"), std::string::npos)
        << e.what();
  }
}

TEST_F(SequenceDir, DirectoryWithoutFramesIsAnError) {
  touch({"readme.txt"});
  EXPECT_THROW(resolve_sequence(dir_.string()), InputError);
}

// A frame whose link is broken (a cache on a volume not mounted, a render farm's link to a
// file not written yet) is listed, so that reading it fails naming it; left out, the run would
// check the other frames and pass. Links to files are followed as the files.
TEST_F(SequenceDir, BrokenLinksAreListedAsFrames) {
  touch({"a.0001.obj", "a.0002.obj"});
  fs::create_symlink(dir_ / "a.0002.obj", dir_ / "a.0003.obj");
  fs::create_symlink(dir_ / "missing.obj", dir_ / "a.0004.obj");
  fs::create_symlink(dir_ / "missing.txt", dir_ / "notes.txt");  // not a frame's name
  const Names expected = {
      {1, "a.0001.obj"}, {2, "a.0002.obj"}, {3, "a.0003.obj"}, {4, "a.0004.obj"}};
  EXPECT_EQ(names(resolve_sequence(dir_.string())), expected);
  EXPECT_EQ(names(resolve_sequence(at("a.%04d.obj"))), expected);
  EXPECT_EQ(names(resolve_sequence(at("a.*.obj"))), expected);
}

TEST_F(SequenceDir, PrintfPatternMatchesWhatPrintfWrites) {
  touch({"dress.0001.obj", "dress.0010.obj", "dress.12345.obj", "dress.001.obj", "dress.00002.obj",
         "dress.0003.ply", "body.0001.obj", "dress.-001.obj", "dress.00x1.obj"});
  EXPECT_EQ(names(resolve_sequence(at("dress.%04d.obj"))), (Names{{-1, "dress.-001.obj"},
                                                                  {1, "dress.0001.obj"},
                                                                  {10, "dress.0010.obj"},
                                                                  {12345, "dress.12345.obj"}}));
  // printf("%03d", 10) is "010": "0010" is not frame 10 at width 3.
  EXPECT_EQ(names(resolve_sequence(at("dress.%03d.obj"))),
            (Names{{1, "dress.001.obj"}, {12345, "dress.12345.obj"}}));
}

TEST_F(SequenceDir, UnpaddedTokensMatchNumbersWithoutLeadingZeros) {
  touch({"s1.obj", "s20.obj", "s0.obj", "s007.obj", "s.obj"});
  const Names unpadded{{0, "s0.obj"}, {1, "s1.obj"}, {20, "s20.obj"}};
  EXPECT_EQ(names(resolve_sequence(at("s%d.obj"))), unpadded);
  EXPECT_EQ(names(resolve_sequence(at("s$F.obj"))), unpadded);
  EXPECT_EQ(names(resolve_sequence(at("s#.obj"))), unpadded);
  EXPECT_EQ(names(resolve_sequence(at("s@.obj"))), unpadded);
}

TEST_F(SequenceDir, HashAtAndHoudiniTokensGiveTheWidth) {
  touch({"c_0001.ply", "c_0002.ply", "c_003.ply", "c_1000.ply"});
  const Names four{{1, "c_0001.ply"}, {2, "c_0002.ply"}, {1000, "c_1000.ply"}};
  EXPECT_EQ(names(resolve_sequence(at("c_####.ply"))), four);
  EXPECT_EQ(names(resolve_sequence(at("c_@@@@.ply"))), four);
  EXPECT_EQ(names(resolve_sequence(at("c_$F4.ply"))), four);
  EXPECT_EQ(names(resolve_sequence(at("c_%04d.ply"))), four);
  EXPECT_EQ(names(resolve_sequence(at("c_###.ply"))),
            (Names{{3, "c_003.ply"}, {1000, "c_1000.ply"}}));
}

TEST_F(SequenceDir, PatternRelativeToTheWorkingDirectory) {
  touch({"a.0001.obj", "a.0002.obj"});
  const fs::path old = fs::current_path();
  fs::current_path(dir_);
  std::vector<Frame> frames;
  EXPECT_NO_THROW(frames = resolve_sequence("a.####.obj"));
  fs::current_path(old);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].path, fs::path("a.0002.obj"));
}

TEST_F(SequenceDir, GlobsNumberFilesByTheirLastDigits) {
  touch({"take2_f9.obj", "take2_f10.obj", "take2_f11.ply", "take3_f1.obj", "other.obj"});
  EXPECT_EQ(names(resolve_sequence(at("take2_*.obj"))),
            (Names{{9, "take2_f9.obj"}, {10, "take2_f10.obj"}}));
  EXPECT_EQ(names(resolve_sequence(at("take?_f1*"))),
            (Names{{1, "take3_f1.obj"}, {10, "take2_f10.obj"}, {11, "take2_f11.ply"}}));
  EXPECT_EQ(names(resolve_sequence(at("take[2]_f1[0-9].*"))),
            (Names{{10, "take2_f10.obj"}, {11, "take2_f11.ply"}}));
  EXPECT_EQ(names(resolve_sequence(at("take[!2]_*"))), (Names{{1, "take3_f1.obj"}}));
  EXPECT_EQ(names(resolve_sequence(at("*f9*"))), (Names{{9, "take2_f9.obj"}}));
}

// Glob brackets as fnmatch(3) reads them (the expected sets are glibc's fnmatch with
// FNM_NOESCAPE on these names): negation by ! or ^, a ] first in a class is a member, a range
// holds both its ends, a - last is a member, an unclosed [ is itself, and a * may match nothing.
TEST_F(SequenceDir, GlobBracketsAndStarsMatchAsFnmatchDoes) {
  touch({"va_1.obj", "vc_2.obj", "vd_3.obj", "v]_4.obj", "v[_5.obj", "v^_6.obj", "v-_7.obj",
         "v9_8.obj", "v0_9.obj", "v!_10.obj"});
  const auto numbers = [&](const std::string& glob) {
    std::vector<int64_t> out;
    for (const Frame& f : resolve_sequence(at(glob))) out.push_back(f.number);
    return out;
  };
  using Numbers = std::vector<int64_t>;
  EXPECT_EQ(numbers("v[!a]_*"), (Numbers{2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(numbers("v[^a]_*"), (Numbers{2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(numbers("v[]]_*"), (Numbers{4}));
  EXPECT_EQ(numbers("v[!]]_*"), (Numbers{1, 2, 3, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(numbers("v[a-c]_*"), (Numbers{1, 2}));
  EXPECT_EQ(numbers("v[0-9]_*"), (Numbers{8, 9}));
  EXPECT_EQ(numbers("v[a-]_*"), (Numbers{1, 7}));
  EXPECT_EQ(numbers("v[_*"), (Numbers{5}));
  EXPECT_EQ(numbers("vc_2.obj*"), (Numbers{2}));
}

TEST_F(SequenceDir, NothingMatchedNamesThePattern) {
  touch({"dress.001.obj"});
  for (const std::string& spec : {at("dress.%04d.obj"), at("dress.*.ply"), at("nothing.obj")}) {
    try {
      resolve_sequence(spec);
      ADD_FAILURE() << spec << " matched";
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), spec);
      EXPECT_EQ(std::string(e.what()).rfind(spec + ": ", 0), 0u) << e.what();
    }
  }
  const fs::path missing = dir_ / "missing_dir";
  try {
    resolve_sequence((missing / "f.%04d.obj").string());
    ADD_FAILURE() << "a pattern in a missing directory resolved";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("directory '" + missing.string() + "' does not exist"),
              std::string::npos)
        << e.what();
  }
}

// The same with only two files: one numbered frame and one without digits.
TEST_F(SequenceDir, AFileWithoutDigitsBesideOneFrameIsAnError) {
  touch({"a.0001.obj", "rest.obj"});
  EXPECT_THROW(resolve_sequence(dir_.string()), InputError);
  EXPECT_THROW(resolve_sequence(at("*.obj")), InputError);
}

// A rest pose or a stray export beside a cache would be frame 0, checked first, and set the
// topology of every frame after it.
TEST_F(SequenceDir, AFileWithoutDigitsAmongFramesIsAnError) {
  touch({"a.0001.obj", "a.0002.obj", "rest.obj", "bind.obj", "t.obj"});
  for (const std::string& spec : {dir_.string(), at("*.obj")}) {
    try {
      resolve_sequence(spec);
      ADD_FAILURE() << spec << " resolved";
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), spec);
      // The first by name, on every filesystem.
      EXPECT_NE(std::string(e.what()).find("bind.obj' has no digits in its name"),
                std::string::npos)
          << e.what();
    }
  }
  // A pattern names only numbered files; a glob may leave it out.
  const Names numbered{{1, "a.0001.obj"}, {2, "a.0002.obj"}};
  EXPECT_EQ(names(resolve_sequence(at("a.%04d.obj"))), numbered);
  EXPECT_EQ(names(resolve_sequence(at("a.*.obj"))), numbered);
  // Alone it is frame 0, in a directory as on its own.
  fs::create_directories(dir_ / "alone");
  std::ofstream(dir_ / "alone" / "body.obj") << "v 0 0 0\n";
  EXPECT_EQ(names(resolve_sequence((dir_ / "alone").string())), (Names{{0, "body.obj"}}));
}

// Frames named by their number alone (1.obj, 2.obj, 10.obj): the digits begin the name, and
// every one of them counts, in a directory, a glob and a pattern alike.
TEST_F(SequenceDir, FramesNamedByTheirNumberAlone) {
  touch({"1.obj", "2.obj", "10.obj"});
  const Names expected{{1, "1.obj"}, {2, "2.obj"}, {10, "10.obj"}};
  EXPECT_EQ(names(resolve_sequence(dir_.string())), expected);
  EXPECT_EQ(names(resolve_sequence(at("*.obj"))), expected);
  EXPECT_EQ(names(resolve_sequence(at("%d.obj"))), expected);
}

TEST_F(SequenceDir, APatternMatchingNothingNamesAFileOfAnotherWidth) {
  touch({"drape.0001.obj", "drape.0002.obj", "coat.12.obj", "other.0001.ply"});
  EXPECT_NE(message("drape.@.obj")
                .find("'drape.0001.obj' has its frame number padded to 4 "
                      "digits: write %04d, #### or $F4"),
            std::string::npos)
      << message("drape.@.obj");
  EXPECT_NE(message("coat.%04d.obj")
                .find("'coat.12.obj' has its frame number unpadded: write "
                      "%d, # or $F"),
            std::string::npos)
      << message("coat.%04d.obj");
  // No file of that prefix and suffix: no hint.
  EXPECT_EQ(message("hat.%04d.obj").find("has its frame number"), std::string::npos);
  EXPECT_EQ(message("other.@@.obj").find("has its frame number"), std::string::npos);
}

// The hint needs digits where the token goes: "hat..obj" has none (nothing to hint at), and
// "coat.0.obj" is frame 0 unpadded, not a number padded to one digit.
TEST_F(SequenceDir, AnOtherWidthHintNeedsAFrameNumberWhereTheTokenGoes) {
  touch({"hat..obj", "coat.0.obj"});
  EXPECT_EQ(message("hat.%04d.obj").find("has its frame number"), std::string::npos)
      << message("hat.%04d.obj");
  EXPECT_NE(message("coat.%04d.obj")
                .find("'coat.0.obj' has its frame number unpadded: write %d, # or $F"),
            std::string::npos)
      << message("coat.%04d.obj");
}

TEST_F(SequenceDir, BadPatternsAreUsageErrors) {
  EXPECT_THROW(resolve_sequence(""), UsageError);
  EXPECT_THROW(resolve_sequence(at("a.%04d.%04d.obj")), UsageError);
  EXPECT_THROW(resolve_sequence(at("a_####_*.obj")), UsageError);
  // Each of the glob characters, in the prefix as in the suffix.
  EXPECT_THROW(resolve_sequence(at("a_####_[ab].obj")), UsageError);
  EXPECT_THROW(resolve_sequence(at("a?_%04d.obj")), UsageError);
}

TEST(FrameNumber, LastRunOfDigitsInTheStem) {
  EXPECT_EQ(frame_number_from_name("shots/sh010/dress.0042.obj"), 42);
  EXPECT_EQ(frame_number_from_name("cloth_ball92.ply"), 92);
  EXPECT_EQ(frame_number_from_name("v2/body.obj"), 0);
  EXPECT_EQ(frame_number_from_name("a12b34c.ply"), 34);
  EXPECT_EQ(frame_number_from_name("frame.obj2"), 0);  // digits of the extension do not count
  EXPECT_EQ(frame_number_from_name("cache/1001.obj"), 1001);  // a name of digits alone
  EXPECT_THROW(frame_number_from_name("f99999999999999999999.obj"), InputError);
}

TEST(FrameSelection, DefaultSelectsEverything) {
  const FrameSelection all;
  EXPECT_TRUE(all.selects_all());
  EXPECT_TRUE(all.contains(-5));
  EXPECT_TRUE(all.contains(1000000));
}

TEST(FrameSelection, Range) {
  const FrameSelection s = FrameSelection::parse("1-240");
  EXPECT_FALSE(s.selects_all());
  EXPECT_FALSE(s.contains(0));
  EXPECT_TRUE(s.contains(1));
  EXPECT_TRUE(s.contains(120));
  EXPECT_TRUE(s.contains(240));
  EXPECT_FALSE(s.contains(241));
}

TEST(FrameSelection, RangeWithStepCountsFromTheFirstFrame) {
  const FrameSelection s = FrameSelection::parse("1-240x5");
  std::vector<int64_t> kept;
  for (int64_t f = -10; f <= 260; ++f)
    if (s.contains(f)) kept.push_back(f);
  ASSERT_EQ(kept.size(), 48u);
  EXPECT_EQ(kept.front(), 1);
  EXPECT_EQ(kept[1], 6);
  EXPECT_EQ(kept.back(), 236);
}

TEST(FrameSelection, ListsSinglesBlanksAndNegatives) {
  const FrameSelection s = FrameSelection::parse(" 1-10, 20-30 ,7,-12--10,-3");
  for (int64_t f : {1, 5, 10, 20, 30, 7, -12, -11, -10, -3}) EXPECT_TRUE(s.contains(f)) << f;
  for (int64_t f : {0, 11, 19, 31, -9, -13, -4, -2}) EXPECT_FALSE(s.contains(f)) << f;
  EXPECT_EQ(s.text(), " 1-10, 20-30 ,7,-12--10,-3");
  const FrameSelection one = FrameSelection::parse("7");
  EXPECT_TRUE(one.contains(7));
  EXPECT_FALSE(one.contains(8));
}

TEST(FrameSelection, HugeRangesDoNotOverflow) {
  const FrameSelection s = FrameSelection::parse("-9223372036854775807-9223372036854775807x2");
  EXPECT_TRUE(s.contains(-9223372036854775807));
  EXPECT_TRUE(s.contains(1));
  EXPECT_FALSE(s.contains(0));
}

TEST(FrameSelection, BadSelectionsAreUsageErrorsQuotingTheItem) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"", "empty item"},
      {"1,,3", "empty item"},
      {"1-10,", "empty item"},
      {"a", "'a'"},
      {"1-", "'1-'"},
      {"1-x", "'1-x'"},
      {"10-1", "'10-1' ends before it starts"},
      {"1-10x0", "step 0"},
      {"1-10x-2", "step -2"},
      {"1-10y", "unexpected 'y'"},
      {"1 2", "unexpected ' 2'"},
      {"1-10x", "'1-10x'"},
      {"5x2", "unexpected 'x2'"},
      {"99999999999999999999", "bad number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    try {
      FrameSelection::parse(c.text);
      ADD_FAILURE() << "accepted";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
}

TEST(SelectFrames, KeepsTheSelectedFramesInOrder) {
  const std::vector<Frame> frames = {{1, "a1.obj"}, {2, "a2.obj"}, {5, "a5.obj"}, {9, "a9.obj"}};
  const std::vector<Frame> kept = select_frames(frames, FrameSelection::parse("2-9x3,1"));
  EXPECT_EQ(kept, (std::vector<Frame>{{1, "a1.obj"}, {2, "a2.obj"}, {5, "a5.obj"}}));
  EXPECT_EQ(select_frames(frames, FrameSelection()), frames);
}

TEST(SelectFrames, SelectingNothingIsAUsageError) {
  const std::vector<Frame> frames = {{1, "a1.obj"}, {2, "a2.obj"}};
  try {
    select_frames(frames, FrameSelection::parse("300-400"));
    FAIL() << "selected nothing without an error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("'300-400' keeps none of the 2 frames (numbered 1 to 2)"),
              std::string::npos)
        << e.what();
  }
}

TEST(AbsentRuns, NamesTheNumbersTheSequenceLacks) {
  const std::vector<Frame> frames = {{1, "a"}, {2, "b"}, {4, "c"}, {5, "d"}, {9, "e"}};
  using Runs = std::vector<std::string>;
  EXPECT_EQ(FrameSelection().absent_runs(frames, 6), Runs{});
  EXPECT_EQ(FrameSelection::parse("1-5").absent_runs(frames, 6), (Runs{"3"}));
  EXPECT_EQ(FrameSelection::parse("1-2,4-5,9").absent_runs(frames, 6), Runs{});
  EXPECT_EQ(FrameSelection::parse("0-12").absent_runs(frames, 6), (Runs{"0", "3", "6-8", "10-12"}));
  EXPECT_EQ(FrameSelection::parse("1-13x4").absent_runs(frames, 6), (Runs{"13"}));
  EXPECT_EQ(FrameSelection::parse("2-20x3").absent_runs(frames, 6), (Runs{"8-20x3"}));
  EXPECT_EQ(FrameSelection::parse("100-200").absent_runs(frames, 6), (Runs{"100-200"}));
  EXPECT_EQ(FrameSelection::parse("0-12").absent_runs(frames, 2), (Runs{"0", "3"}));
  EXPECT_EQ(FrameSelection::parse("3,3").absent_runs(frames, 6), (Runs{"3"}));  // once
  // Whether runs were left out past the most asked for (a run named twice counts once).
  bool more = false;
  EXPECT_EQ(FrameSelection::parse("0-12").absent_runs(frames, 2, &more), (Runs{"0", "3"}));
  EXPECT_TRUE(more);
  EXPECT_EQ(FrameSelection::parse("0-12").absent_runs(frames, 4, &more).size(), 4u);
  EXPECT_FALSE(more);
  EXPECT_EQ(FrameSelection::parse("3,3").absent_runs(frames, 1, &more), (Runs{"3"}));
  EXPECT_FALSE(more);
  // Numbers at the ends of int64 do not overflow.
  const int64_t most = std::numeric_limits<int64_t>::max();
  const std::vector<Frame> far = {{most - 1, "x"}};
  EXPECT_EQ(
      FrameSelection::parse(std::to_string(most - 3) + "-" + std::to_string(most))
          .absent_runs(far, 6),
      (Runs{std::to_string(most - 3) + "-" + std::to_string(most - 2), std::to_string(most)}));
}

// absent_runs against enumerating every number each item names, on random sequences and
// selections: the runs, expanded, are the numbers named and not present, item by item.
TEST(AbsentRuns, AgreeWithEnumeratingEveryNumber) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<Frame> frames;
    for (int64_t n = -5; n <= 40; ++n)
      if (rng() % 3 != 0) frames.push_back({n, "f"});
    std::string text;
    const int items = 1 + static_cast<int>(rng() % 3);
    for (int i = 0; i < items; ++i) {
      const int64_t first = static_cast<int64_t>(rng() % 50) - 8;
      const int64_t last = first + static_cast<int64_t>(rng() % 20);
      const int64_t step = 1 + static_cast<int64_t>(rng() % 4);
      text += (i ? "," : "") + std::to_string(first) + "-" + std::to_string(last) + "x" +
              std::to_string(step);
    }
    SCOPED_TRACE(text);
    const FrameSelection selection = FrameSelection::parse(text);
    std::vector<int64_t> expected;  // item by item, each in order, a number once
    for (size_t comma = 0, start = 0; start <= text.size(); start = comma + 1) {
      comma = text.find(',', start);
      if (comma == std::string::npos) comma = text.size();
      const FrameSelection item = FrameSelection::parse(text.substr(start, comma - start));
      for (int64_t n = -20; n <= 80; ++n) {
        const bool present = std::any_of(frames.begin(), frames.end(),
                                         [&](const Frame& f) { return f.number == n; });
        if (item.contains(n) && !present &&
            std::find(expected.begin(), expected.end(), n) == expected.end())
          expected.push_back(n);
      }
    }
    std::vector<int64_t> got;
    for (const std::string& run : selection.absent_runs(frames, 1000)) {
      const FrameSelection as_item = FrameSelection::parse(run);
      for (int64_t n = -20; n <= 80; ++n)
        if (as_item.contains(n) && std::find(got.begin(), got.end(), n) == got.end())
          got.push_back(n);
    }
    EXPECT_EQ(got, expected);
  }
}

TEST(FrameGaps, NamesTheNumbersMissingOnTheSequencesOwnGrid) {
  const auto frames_of = [](std::initializer_list<int64_t> numbers) {
    std::vector<Frame> frames;
    for (int64_t n : numbers) frames.push_back({n, "f"});
    return frames;
  };
  using Runs = std::vector<std::string>;
  FrameGaps gaps = frame_gaps(frames_of({1, 2, 3, 5, 8, 10, 12}), 6);
  EXPECT_EQ(gaps.runs, (Runs{"4", "6-7", "9", "11"}));
  EXPECT_EQ(gaps.step, 1);
  EXPECT_EQ(gaps.first, 1);
  EXPECT_EQ(gaps.last, 12);
  // Every 5th frame written: no gap, until one of them is lost.
  EXPECT_EQ(frame_gaps(frames_of({1, 6, 11, 16, 21}), 6).runs, Runs{});
  gaps = frame_gaps(frames_of({1, 6, 11, 31}), 6);
  EXPECT_EQ(gaps.runs, (Runs{"16-26x5"}));
  EXPECT_EQ(gaps.step, 5);
  EXPECT_EQ(frame_gaps(frames_of({-5, -3, 3}), 6).runs, (Runs{"-1-1x2"}));
  gaps = frame_gaps(frames_of({1, 2, 4, 6, 8, 10, 12, 14}), 2);
  EXPECT_EQ(gaps.runs, (Runs{"3", "5"}));
  EXPECT_TRUE(gaps.more);
  gaps = frame_gaps(frames_of({1, 2, 4, 6}), 2);
  EXPECT_EQ(gaps.runs, (Runs{"3", "5"}));
  EXPECT_FALSE(gaps.more);  // exactly as many runs as asked for: nothing left out
  // Two frames, or one, make their own grid.
  EXPECT_EQ(frame_gaps(frames_of({1, 100}), 6).runs, Runs{});
  EXPECT_EQ(frame_gaps(frames_of({7}), 6).runs, Runs{});
  EXPECT_EQ(frame_gaps({}, 6).runs, Runs{});
  // The ends of int64.
  const int64_t most = std::numeric_limits<int64_t>::max();
  const int64_t least = std::numeric_limits<int64_t>::min();
  EXPECT_EQ(frame_gaps(frames_of({least, 0, most}), 6).runs,
            (Runs{std::to_string(least + 1) + "-" + std::to_string(-1),
                  "1-" + std::to_string(most - 1)}));
}

// frame_gaps against enumerating: the step is the largest that divides every difference, and the
// runs, expanded, are the numbers on that grid between the first and last frame that no frame has.
TEST(FrameGaps, AgreeWithEnumeratingEveryNumber) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3000; ++trial) {
    const int64_t spacing = 1 + static_cast<int64_t>(rng() % 4);
    const int64_t offset = static_cast<int64_t>(rng() % 7) - 3;
    std::vector<Frame> frames;
    for (int64_t k = -4; k <= 20; ++k)
      if (rng() % 3 != 0) frames.push_back({offset + k * spacing, "f"});
    if (frames.size() < 3) continue;
    std::string listed;
    for (const Frame& f : frames) listed += std::to_string(f.number) + " ";
    SCOPED_TRACE(listed);
    int64_t step = 0;
    for (int64_t d = frames.back().number - frames.front().number; d >= 1; --d) {
      const bool divides = std::all_of(frames.begin() + 1, frames.end(), [&](const Frame& f) {
        return (f.number - frames.front().number) % d == 0;
      });
      if (divides) {
        step = d;
        break;
      }
    }
    std::vector<int64_t> expected;
    for (int64_t n = frames.front().number; n <= frames.back().number; n += step)
      if (std::none_of(frames.begin(), frames.end(), [&](const Frame& f) { return f.number == n; }))
        expected.push_back(n);
    const FrameGaps gaps = frame_gaps(frames, 1000);
    EXPECT_EQ(gaps.step, step);
    std::vector<int64_t> got;
    for (const std::string& run : gaps.runs) {
      const FrameSelection as_item = FrameSelection::parse(run);
      for (int64_t n = -100; n <= 100; ++n)
        if (as_item.contains(n)) got.push_back(n);
    }
    EXPECT_EQ(got, expected);
  }
}

}  // namespace
}  // namespace snag::seq
