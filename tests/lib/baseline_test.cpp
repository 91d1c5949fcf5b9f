// The baseline of accepted pairs (--baseline): a pairs.csv read back by its header's names,
// each frame's pairs marked against hand-listed expectations, what the run made of the file,
// and every malformed file refused with its line.
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "report_files.h"
#include "snag/error.h"
#include "snag/report/baseline.h"
#include "snag/report/csv.h"
#include "snag/report/report.h"

namespace snag::report {
namespace {

using detect::PairKind;

constexpr PairKind kCrossing = PairKind::crossing;
constexpr PairKind kTouching = PairKind::touching;

/// A frame record of a 1,000-triangle mesh with these pairs (object 0 throughout unless a pair
/// says otherwise).
FrameRecord frame_with(int64_t number, std::vector<Pair> pairs) {
  FrameRecord f;
  f.frame = number;
  f.triangles = 1000;
  f.pairs = std::move(pairs);
  return f;
}

/// The (a, b) of the pairs `frame` has marked accepted.
std::set<std::pair<int32_t, int32_t>> accepted_of(const FrameRecord& frame) {
  std::set<std::pair<int32_t, int32_t>> accepted;
  for (const Pair& p : frame.pairs)
    if (p.accepted) accepted.insert({p.a, p.b});
  return accepted;
}

std::vector<ObjectInput> two_objects() {
  return {
      {"dress", "cloth", "dress.%04d.obj", std::nullopt, false, std::nullopt, 10, 20, ""},
      {"body, \"v2\"", "obstacle", "body.obj", std::nullopt, true, std::nullopt, 8, 12, "closed"}};
}

/// What use() should say: the entries, those of the frames checked, the lines of those that
/// matched no pair, and the rows marked accepted 0.
BaselineUse expected_use(int64_t entries, int64_t checked, std::vector<int64_t> unmatched_lines,
                         int64_t left_out = 0) {
  const auto unmatched = static_cast<int64_t>(unmatched_lines.size());
  return {entries, left_out, checked, unmatched, std::move(unmatched_lines)};
}

/// The InputError `parse` throws for `text`: its line and message, for EXPECTs.
std::pair<int64_t, std::string> refusal(const std::string& text,
                                        const std::vector<ObjectInput>& objects = {}) {
  try {
    Baseline::parse(text, "accepted.csv", objects);
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), "accepted.csv");
    return {e.line(), e.what()};
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return {-1, ""};
}

TEST(Baseline, APairsCsvAsSnagWritesItAcceptsItsPairsInTheirFrames) {
  // A run's own reports, read back: frame 5's two pairs and frame 7's one (a run without a
  // baseline: no accepted column, RowsMarkedAcceptedZeroAreLeftOut has one).
  Report run;
  run.frames.push_back(frame_with(5, {{1, 9, kCrossing, 1, 9}, {2, 3, kTouching, 2, 2}}));
  run.frames.push_back(frame_with(7, {{4, 6, kCrossing, 4, 6}}));
  std::ostringstream pairs_csv;
  write_pairs_csv(pairs_csv, run);
  Baseline baseline = Baseline::parse(pairs_csv.str(), "earlier.csv", {});
  EXPECT_EQ(baseline.entries(), 3);

  // Frame 5 again: its two pairs, one new one, and frame 7's pair (accepted in 7 only).
  FrameRecord five =
      frame_with(5, {{1, 9, kCrossing}, {2, 3, kTouching}, {2, 8, kCrossing}, {4, 6, kCrossing}});
  baseline.mark(five);
  EXPECT_EQ(accepted_of(five), (std::set<std::pair<int32_t, int32_t>>{{1, 9}, {2, 3}}));
  EXPECT_EQ(baseline.use(), expected_use(3, 2, {}));

  // Frame 6 is not in the file: nothing accepted, nothing more checked.
  FrameRecord six = frame_with(6, {{1, 9, kCrossing}});
  baseline.mark(six);
  EXPECT_TRUE(accepted_of(six).empty());
  EXPECT_EQ(baseline.use(), expected_use(3, 2, {}));

  // Frame 7 without its pair: its entry is checked and matched nothing.
  FrameRecord seven = frame_with(7, {});
  baseline.mark(seven);
  EXPECT_EQ(baseline.use(), expected_use(3, 3, {4}));
}

TEST(Baseline, MarkingSetsAndClearsEveryPairsMark) {
  Baseline baseline = Baseline::parse("frame,face_a,face_b\n3,0,1\n", "b.csv", {});
  // A record that came marked (from an earlier baseline, say) is marked again from scratch.
  FrameRecord f =
      frame_with(3, {{0, 1, kCrossing, 0, 0, 0, 0, false}, {0, 2, kTouching, 0, 0, 0, 0, true}});
  baseline.mark(f);
  EXPECT_TRUE(f.pairs[0].accepted);
  EXPECT_FALSE(f.pairs[1].accepted);
}

TEST(Baseline, ColumnsAreFoundByNameInAnyOrderAndOthersIgnored) {
  // Spaces around names and values typed by hand; a row that stops before its optional kind.
  Baseline baseline = Baseline::parse(
      "note, face_b ,kind,frame,face_a\n"
      "\"seam, left\",12,crossing,40,11\n"
      "button, 30 ,touching, 40,2\n"
      "cut short,7\t,\t, 40 ,3\n"
      "\t\"tabbed\", 50 ,crossing,\t40\t, 2\n",
      "b.csv", {});
  FrameRecord f = frame_with(
      40, {{11, 12, kCrossing}, {2, 30, kTouching}, {2, 31, kTouching}, {3, 7, kCrossing}});
  baseline.mark(f);
  EXPECT_EQ(accepted_of(f), (std::set<std::pair<int32_t, int32_t>>{{11, 12}, {2, 30}, {3, 7}}));
  FrameRecord tabbed = frame_with(40, {{2, 50, kCrossing}});
  baseline.mark(tabbed);
  EXPECT_TRUE(tabbed.pairs[0].accepted);
  Baseline short_rows = Baseline::parse("frame,face_a,face_b,kind,poly_a\n40,3,7\n", "b.csv", {});
  FrameRecord g = frame_with(40, {{3, 7, kCrossing}});
  short_rows.mark(g);
  EXPECT_TRUE(g.pairs[0].accepted);
}

TEST(Baseline, RowsMarkedAcceptedZeroAreLeftOut) {
  // The pairs.csv of a run with a baseline: its new pairs are marked 0, and taking the file as
  // the next baseline must not accept them unseen. 1 or nothing accepts.
  Baseline baseline = Baseline::parse(
      "frame,face_a,face_b,kind,poly_a,poly_b,accepted\n"
      "5,1,9,crossing,1,9,1\n"
      "5,2,8,crossing,2,8,0\n"
      "5,3,7,touching,3,7,\n"
      "5,4,6,touching,4,6,0\n",
      "b.csv", {});
  FrameRecord f =
      frame_with(5, {{1, 9, kCrossing}, {2, 8, kCrossing}, {3, 7, kTouching}, {4, 6, kTouching}});
  baseline.mark(f);
  EXPECT_EQ(accepted_of(f), (std::set<std::pair<int32_t, int32_t>>{{1, 9}, {3, 7}}));
  EXPECT_EQ(baseline.use(), expected_use(2, 2, {}, 2));
  const auto [line, message] = refusal("frame,face_a,face_b,accepted\n5,1,9,yes\n");
  EXPECT_EQ(line, 2);
  EXPECT_NE(message.find("accepted: expected 1, 0 or nothing, got 'yes'"), std::string::npos)
      << message;
}

TEST(Baseline, AFacePastTheFramesTrianglesIsAnErrorWithItsLine) {
  Baseline baseline =
      Baseline::parse("frame,face_a,face_b\n1,0,1\n2,5,999\n*,3,4\n2,5,1000\n", "mine.csv", {});
  FrameRecord one = frame_with(1, {});
  baseline.mark(one);  // the every-frame entry and frame 1's are within 1,000 triangles
  FrameRecord two = frame_with(2, {});
  try {
    baseline.mark(two);
    ADD_FAILURE() << "face 1000 of a 1,000-triangle frame was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), "mine.csv");
    EXPECT_EQ(e.line(), 5);
    EXPECT_NE(std::string(e.what()).find("face 1000 is not a face of frame 2 (1000 triangles)"),
              std::string::npos)
        << e.what();
  }
  // An every-frame entry is bounded by every frame, up to the first whose face list changed:
  // its ids were found in one face list, and a later one may have fewer faces.
  Baseline every = Baseline::parse("frame,face_a,face_b\n*,3,40\n12,3,40\n", "mine.csv", {});
  FrameRecord small = frame_with(9, {});
  small.triangles = 40;
  EXPECT_THROW(every.mark(small), InputError);
  Baseline later = Baseline::parse("frame,face_a,face_b\n*,3,40\n12,3,40\n", "mine.csv", {});
  FrameRecord first = frame_with(9, {{3, 40, kCrossing}});
  later.mark(first);
  EXPECT_TRUE(first.pairs[0].accepted);
  for (const bool changed : {true, false}) {  // the change, then a frame after it
    FrameRecord fewer = frame_with(changed ? 10 : 11, {});
    fewer.triangles = 40;
    fewer.topology_changed = changed;
    EXPECT_NO_THROW(later.mark(fewer));
  }
  // An entry for one frame still is.
  FrameRecord twelve = frame_with(12, {});
  twelve.triangles = 40;
  EXPECT_THROW(later.mark(twelve), InputError);
}

TEST(Baseline, SceneFacesAreBoundedByTheirObjectUnlessItIsAGroup) {
  std::vector<ObjectInput> objects = two_objects();
  const std::string text =
      "frame,face_a,face_b,object_a,object_b\n"
      "1,0,11,dress,\"body, \"\"v2\"\"\"\n";
  FrameRecord f = frame_with(1, {});
  f.objects = {ObjectFrame{}, ObjectFrame{}};
  f.objects[0].triangles = 20;
  f.objects[1].triangles = 11;  // the body's face 11 is not there
  Baseline whole = Baseline::parse(text, "b.csv", objects);
  try {
    whole.mark(f);
    ADD_FAILURE() << "the body's face 11 was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("face 11 is not a face of frame 1 (body, \"v2\": 11 "
                                         "triangles)"),
              std::string::npos)
        << e.what();
  }
  // Either face of a row: here the dress's (object_a), past its 20.
  Baseline dress =
      Baseline::parse("frame,face_a,face_b,object_a,object_b\n1,25,0,dress,\"body, \"\"v2\"\"\"\n",
                      "b.csv", objects);
  EXPECT_THROW(dress.mark(f), InputError);
  // As an OBJ group of a file, the body's ids are the file's: not bounded by its own count.
  objects[1].group = "body";
  Baseline group = Baseline::parse(text, "b.csv", objects);
  EXPECT_NO_THROW(group.mark(f));
}

TEST(Baseline, UnmatchedLinesAreEachEntrysFirstInOrder) {
  // (1, 2) of frame 5 twice (lines 2 and 4), frame 9's entry before frame 3's.
  Baseline baseline =
      Baseline::parse("frame,face_a,face_b\n5,1,2\n9,0,1\n5,2,1\n3,0,1\n", "b.csv", {});
  for (const int64_t number : {3, 5, 9}) {
    FrameRecord f = frame_with(number, {});
    baseline.mark(f);
  }
  EXPECT_EQ(baseline.use(), expected_use(3, 3, {2, 3, 5}));
}

TEST(Baseline, FacesInEitherOrderAreOnePair) {
  Baseline baseline = Baseline::parse("frame,face_a,face_b\n1,9,4\n1,4,9\n2,7,3\n", "b.csv", {});
  EXPECT_EQ(baseline.entries(), 2);  // (4, 9) in frame 1 once, (3, 7) in frame 2
  FrameRecord one = frame_with(1, {{4, 9, kCrossing}});
  FrameRecord two = frame_with(2, {{3, 7, kTouching}});
  baseline.mark(one);
  baseline.mark(two);
  EXPECT_TRUE(one.pairs[0].accepted);
  EXPECT_TRUE(two.pairs[0].accepted);
  EXPECT_EQ(baseline.use(), expected_use(2, 2, {}));
}

TEST(Baseline, AStarFrameAcceptsThePairInEveryFrame) {
  Baseline baseline =
      Baseline::parse("frame,face_a,face_b,kind\n*,5,6,crossing\n8,1,2,\n", "b.csv", {});
  EXPECT_EQ(baseline.use(), expected_use(2, 0, {}));  // nothing checked yet
  for (int64_t number : {-3, 0, 8, 1000000}) {
    FrameRecord f = frame_with(number, {{5, 6, kCrossing}, {1, 2, kCrossing}});
    baseline.mark(f);
    EXPECT_TRUE(f.pairs[0].accepted) << number;
    EXPECT_EQ(f.pairs[1].accepted, number == 8) << number;
  }
  EXPECT_EQ(baseline.use(), expected_use(2, 2, {}));
}

TEST(Baseline, ATouchingEntryAcceptsitsPairOnlyWhileItTouches) {
  const std::string text =
      "frame,face_a,face_b,kind\n"
      "1,0,1,touching\n"  // touching only
      "1,0,2,crossing\n"  // either
      "1,0,3,*\n"         // either
      "1,0,4,\n";         // either
  for (const PairKind kind : {kCrossing, kTouching}) {
    SCOPED_TRACE(kind == kCrossing ? "crossing now" : "touching now");
    Baseline baseline = Baseline::parse(text, "b.csv", {});
    FrameRecord f = frame_with(1, {{0, 1, kind}, {0, 2, kind}, {0, 3, kind}, {0, 4, kind}});
    baseline.mark(f);
    EXPECT_EQ(f.pairs[0].accepted, kind == kTouching);
    EXPECT_TRUE(f.pairs[1].accepted && f.pairs[2].accepted && f.pairs[3].accepted);
    // A touching pair that crosses now leaves its entry unmatched: it got worse.
    EXPECT_EQ(
        baseline.use(),
        expected_use(4, 4, kind == kCrossing ? std::vector<int64_t>{2} : std::vector<int64_t>{}));
  }
  // Without a kind column every entry accepts either kind.
  Baseline kindless = Baseline::parse("frame,face_a,face_b\n1,0,1\n", "b.csv", {});
  FrameRecord f = frame_with(1, {{0, 1, kCrossing}});
  kindless.mark(f);
  EXPECT_TRUE(f.pairs[0].accepted);
}

TEST(Baseline, APairListedTwiceIsOneEntryAcceptingWhatEitherRowAccepts) {
  Baseline baseline = Baseline::parse(
      "frame,face_a,face_b,kind\n2,0,1,touching\n2,1,0,crossing\n2,0,1,touching\n", "b.csv", {});
  EXPECT_EQ(baseline.entries(), 1);
  FrameRecord f = frame_with(2, {{0, 1, kCrossing}});
  baseline.mark(f);
  EXPECT_TRUE(f.pairs[0].accepted);
}

TEST(Baseline, AnEntryForAFrameAndForEveryFrameBothCount) {
  // The frame's own entry accepts touching only; the every-frame one accepts either: the pair
  // crossing now is accepted by the second, and the first matched nothing.
  Baseline baseline =
      Baseline::parse("frame,face_a,face_b,kind\n4,0,1,touching\n*,0,1,crossing\n", "b.csv", {});
  FrameRecord f = frame_with(4, {{0, 1, kCrossing}});
  baseline.mark(f);
  EXPECT_TRUE(f.pairs[0].accepted);
  EXPECT_EQ(baseline.use(), expected_use(2, 2, {2}));
  // Both accepting it: both matched.
  Baseline both = Baseline::parse("frame,face_a,face_b\n4,0,1\n*,0,1\n", "b.csv", {});
  FrameRecord g = frame_with(4, {{0, 1, kCrossing}});
  both.mark(g);
  EXPECT_TRUE(g.pairs[0].accepted);
  EXPECT_EQ(both.use(), expected_use(2, 2, {}));
}

TEST(Baseline, SceneRowsNameTheirObjectsAsThePairsCsvDoes) {
  const std::vector<ObjectInput> objects = two_objects();
  // The second object's name needs CSV quoting; the last row lists the pair body-first.
  Baseline baseline = Baseline::parse(
      "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
      "3,5,2,crossing,5,2,dress,\"body, \"\"v2\"\"\"\n"
      "3,1,4,touching,1,4,dress,dress\n"
      "3,7,0,crossing,7,0,\"body, \"\"v2\"\"\",dress\n",
      "b.csv", objects);
  EXPECT_EQ(baseline.entries(), 3);
  FrameRecord f = frame_with(3, {{0, 7, kCrossing, 0, 7, 0, 1},    // dress 0 - body 7
                                 {1, 4, kTouching, 1, 4, 0, 0},    // dress 1 - dress 4
                                 {2, 5, kCrossing, 2, 5, 0, 1},    // dress 2 - body 5: not listed
                                 {5, 2, kCrossing, 5, 2, 0, 1},    // dress 5 - body 2
                                 {1, 4, kTouching, 1, 4, 0, 1}});  // dress 1 - body 4: not listed
  baseline.mark(f);
  std::vector<bool> marks;
  for (const Pair& p : f.pairs) marks.push_back(p.accepted);
  EXPECT_EQ(marks, (std::vector<bool>{true, true, false, true, false}));
  EXPECT_EQ(baseline.use(), expected_use(3, 3, {}));
}

TEST(Baseline, LinesAreCountedThroughQuotedLineBreaksBlankLinesAndCrlf) {
  // A byte order mark, CRLF line ends, a blank line and a quoted field over two lines: the bad
  // face id is on line 6.
  const std::string text =
      "\xEF\xBB\xBF"
      "frame,face_a,face_b,note\r\n"
      "1,0,1,plain\r\n"
      "\r\n"
      "1,0,2,\"two\r\nlines\"\r\n"
      "1,x,3,bad\r\n";
  const auto [line, message] = refusal(text);
  EXPECT_EQ(line, 6);
  EXPECT_NE(message.find("face_a: expected a face id (a whole number >= 0), got 'x'"),
            std::string::npos)
      << message;
  // Without the bad row the rest reads, the BOM and CRLF included.
  Baseline baseline = Baseline::parse(text.substr(0, text.rfind("1,x")), "b.csv", {});
  EXPECT_EQ(baseline.entries(), 2);
}

TEST(Baseline, MalformedFilesAreRefusedWithTheirLine) {
  struct Case {
    std::string text;
    int64_t line;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"", 0, "empty"},
      {"\n\n", 0, "empty"},
      {"frame,face_a\n1,2\n", 1, "no face_b column"},
      {"face_a,face_b\n1,2\n", 1, "no frame column"},
      {"frame,face_a,face_b,face_a\n", 1, "names column face_a twice"},
      {"frame,face_a,face_b,object_a,object_b\n", 1, "this run checks one mesh"},
      {"frame,face_a,face_b\n1,2\n", 2, "only 2 fields"},
      {"frame,face_a,face_b\n1,-2,3\n", 2, "face_a: expected a face id"},
      {"frame,face_a,face_b\n1,2,3.0\n", 2, "face_b: expected a face id"},
      {"frame,face_a,face_b\n1,2,4294967296\n", 2, "face_b: expected a face id"},
      {"frame,face_a,face_b\n1,2,3 4\n", 2, "face_b: expected a face id"},
      {"frame;face_a;face_b\n1;2;3\n", 1, "no frame column in the header 'frame;face_a;face_b'"},
      {"frame,face_a,face_b\nall,2,3\n", 2, "frame: expected a frame number or *"},
      {"frame,face_a,face_b\n1,2,3\n1,4,4\n", 3, "face 4 paired with itself"},
      {"frame,face_a,face_b,kind\n1,2,3,cross\n", 2, "kind: expected crossing, touching or *"},
      {"frame,face_a,face_b\n1,2,\"3\n", 2, "a quoted field is not closed"},
      {"frame,face_a,face_b\n1,2,3\"4\"\n", 2, "a quote inside an unquoted field"},
      {"frame,face_a,face_b\n1,2,\"3\"4\n", 2, "text after a quoted field's closing quote"},
      {"frame,face_a,face_b\n1,2,3\r4\n", 2, "a carriage return not followed by a line feed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const auto [line, message] = refusal(c.text);
    EXPECT_EQ(line, c.line);
    EXPECT_NE(message.find(c.says), std::string::npos) << message;
  }
}

TEST(Baseline, ObjectColumnsMustFitTheRun) {
  const std::vector<ObjectInput> objects = two_objects();
  {
    const auto [line, message] = refusal("frame,face_a,face_b\n1,2,3\n", objects);
    EXPECT_EQ(line, 1);
    EXPECT_NE(message.find("no object_a and object_b columns"), std::string::npos) << message;
  }
  {
    // A row short of its object columns.
    const auto [line, message] =
        refusal("frame,face_a,face_b,object_a,object_b\n1,0,1,dress\n", objects);
    EXPECT_EQ(line, 2);
    EXPECT_NE(message.find("only 4 fields"), std::string::npos) << message;
  }
  {
    // Blanks around a quoted name are not part of it.
    Baseline baseline = Baseline::parse(
        "frame,face_a,face_b,object_a,object_b\n1, 0, 1, dress , \"body, \"\"v2\"\"\" \n", "b.csv",
        objects);
    EXPECT_EQ(baseline.entries(), 1);
  }
  {
    const auto [line, message] = refusal("frame,face_a,face_b,object_a\n", objects);
    EXPECT_EQ(line, 1);
    EXPECT_NE(message.find("column object_a without object_b"), std::string::npos) << message;
  }
  {
    const auto [line, message] = refusal(
        "frame,face_a,face_b,object_a,object_b\n1,2,3,dress,dress\n1,2,3,dress,body\n", objects);
    EXPECT_EQ(line, 3);
    EXPECT_NE(message.find("object_b: 'body' is not an object of this run (dress, body, \"v2\")"),
              std::string::npos)
        << message;
  }
  {
    // One object's face paired with itself; the same id on two objects is a pair.
    const auto [line, message] = refusal(
        "frame,face_a,face_b,object_a,object_b\n1,2,2,dress,\"body, \"\"v2\"\"\"\n"
        "1,2,2,dress,dress\n",
        objects);
    EXPECT_EQ(line, 3);
    EXPECT_NE(message.find("paired with itself"), std::string::npos) << message;
  }
}

TEST(Baseline, ReadsAFileAndNamesOneThatCannotBeRead) {
  const TempDir tmp;
  const std::filesystem::path path = tmp.path() / "accepted.csv";
  std::ofstream(path) << "frame,face_a,face_b\n1,2,3\n";
  EXPECT_EQ(Baseline::read(path, {}).entries(), 1);
  // Without a final line end, and a header alone (which accepts nothing).
  EXPECT_EQ(Baseline::parse("frame,face_a,face_b\n1,2,3", "b.csv", {}).entries(), 1);
  EXPECT_EQ(Baseline::parse("frame,face_a,face_b\n", "b.csv", {}).entries(), 0);
  try {
    Baseline::read(tmp.path(), {});
    ADD_FAILURE() << "a directory was read as a baseline";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a directory; expected a pairs.csv file"),
              std::string::npos)
        << e.what();
  }
  try {
    Baseline::read(tmp.path() / "missing.csv", {});
    ADD_FAILURE() << "a missing baseline was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace snag::report
