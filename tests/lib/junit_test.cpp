// The JUnit XML report: exact bytes for a small hand-built run, the failures --fail-on and a
// baseline decide, the listed pairs' limit, and text escaped for XML.
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "snag/report/junit.h"
#include "snag/report/report.h"

namespace snag::report {
namespace {

using detect::PairKind;

FrameRecord frame_with(int64_t number, std::string file, std::vector<Pair> pairs, double seconds) {
  FrameRecord f;
  f.frame = number;
  f.file = std::move(file);
  f.pairs = std::move(pairs);
  // The frame's time is all of its stages', as frames.csv's seconds.
  f.times.refit = seconds / 4;
  f.times.traverse = seconds / 2;
  f.times.classify = seconds / 4;
  return f;
}

std::string written(const JunitReport& junit) {
  std::ostringstream out;
  junit.write(out);
  return out.str();
}

TEST(Junit, ASmallRunByteForByte) {
  JunitReport junit("shots/a&b.%04d.obj", FailOn::crossing);
  junit.add(frame_with(1, "shots/a&b.0001.obj", {}, 0.001));
  junit.add(frame_with(2, "shots/a&b.0002.obj", {{3, 9, PairKind::touching, 3, 4}}, 0.002));
  junit.add(frame_with(3, "shots/a&b.0003.obj",
                       {{1, 2, PairKind::crossing, 1, 1},
                        {3, 9, PairKind::touching, 3, 4},
                        {4, 8, PairKind::crossing, 4, 4}},
                       0.0005));
  EXPECT_EQ(written(junit),
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<testsuites name=\"snag check\" tests=\"3\" failures=\"1\" time=\"0.003500\">\n"
            "  <testsuite name=\"shots/a&amp;b.%04d.obj\" tests=\"3\" failures=\"1\" skipped=\"0\" "
            "errors=\"0\" time=\"0.003500\">\n"
            "    <testcase classname=\"snag.check\" name=\"frame 1: shots/a&amp;b.0001.obj\" "
            "time=\"0.001000\"/>\n"
            "    <testcase classname=\"snag.check\" name=\"frame 2: shots/a&amp;b.0002.obj\" "
            "time=\"0.002000\"/>\n"
            "    <testcase classname=\"snag.check\" name=\"frame 3: shots/a&amp;b.0003.obj\" "
            "time=\"0.000500\">\n"
            "      <failure type=\"crossing\" message=\"2 crossing pairs (--fail-on crossing)\">"
            "frame,face_a,face_b,kind,poly_a,poly_b\n"
            "3,1,2,crossing,1,1\n"
            "3,4,8,crossing,4,4\n"
            "</failure>\n"
            "    </testcase>\n"
            "  </testsuite>\n"
            "</testsuites>\n");
}

TEST(Junit, FailuresAreThoseOfFailOnAndTheBaseline) {
  const std::vector<Pair> touching = {{3, 9, PairKind::touching, 3, 9}};
  std::vector<Pair> mixed = {{1, 2, PairKind::crossing, 1, 2}, {4, 8, PairKind::crossing, 4, 8}};
  mixed[0].accepted = true;
  const auto failures = [&](FailOn fail_on) {
    JunitReport junit("s", fail_on);
    junit.add(frame_with(1, "f1", touching, 0));
    junit.add(frame_with(2, "f2", mixed, 0));
    return written(junit);
  };
  const std::string any = failures(FailOn::any);
  EXPECT_NE(any.find("failures=\"2\""), std::string::npos) << any;
  EXPECT_NE(any.find("<failure type=\"any\""), std::string::npos) << any;
  EXPECT_NE(any.find("message=\"1 intersecting pair (--fail-on any)\">frame,face_a,face_b,kind,"
                     "poly_a,poly_b\n1,3,9,touching,3,9\n</failure>"),
            std::string::npos)
      << any;
  // Frame 2's accepted crossing is not listed; the message says the baseline had a say.
  EXPECT_NE(any.find("message=\"1 intersecting pair the baseline does not accept (--fail-on "
                     "any)\">frame,face_a,face_b,kind,poly_a,poly_b\n2,4,8,crossing,4,8\n"),
            std::string::npos)
      << any;
  const std::string crossing = failures(FailOn::crossing);
  EXPECT_NE(crossing.find("failures=\"1\""), std::string::npos) << crossing;
  EXPECT_NE(crossing.find("name=\"frame 1: f1\" time=\"0.000000\"/>"), std::string::npos)
      << crossing;
  const std::string none = failures(FailOn::none);
  EXPECT_NE(none.find("failures=\"0\""), std::string::npos) << none;
  EXPECT_EQ(none.find("<failure"), std::string::npos) << none;
}

TEST(Junit, AFailureListsItsFirstPairsAndCountsTheRest) {
  std::vector<Pair> pairs;
  for (int32_t a = 0; a < 60; ++a) pairs.push_back({a, a + 100, PairKind::crossing, a, a + 100});
  std::vector<ObjectInput> objects(2);
  objects[0].name = "dress";
  objects[1].name = "body <v2>";
  for (Pair& p : pairs) p.object_b = 1;
  JunitReport junit("scene.json", FailOn::crossing, objects);
  junit.add(frame_with(7, "dress.0007.obj", pairs, 0.25));
  const std::string xml = written(junit);
  EXPECT_NE(xml.find("message=\"60 crossing pairs (--fail-on crossing)\">frame,face_a,face_b,"
                     "kind,poly_a,poly_b,object_a,object_b\n7,0,100,crossing,0,100,dress,body "
                     "&lt;v2&gt;\n"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("7,49,149,crossing,49,149,dress,body &lt;v2&gt;\n... and 10 more\n</failure>"),
            std::string::npos)
      << xml;
  EXPECT_EQ(xml.find("7,50,150"), std::string::npos) << xml;
}

TEST(Junit, TextIsEscapedAndWhatXmlCannotHoldReplaced) {
  EXPECT_EQ(xml_escaped("a&b <c> \"d\" 'e'", false),
            "a&amp;b &lt;c&gt; &quot;d&quot; &apos;e&apos;");
  // A carriage return, and in an attribute a tab and a line feed, as references: a parser would
  // read them back as a line feed and as spaces.
  EXPECT_EQ(xml_escaped("tab\tline\ncr\r", false), "tab\tline\ncr&#13;");
  EXPECT_EQ(xml_escaped("tab\tline\ncr\r", true), "tab&#9;line&#10;cr&#13;");
  EXPECT_EQ(xml_escaped("dr\xc3\xa9pe \xe2\x82\xac \xf0\x9f\x91\x97", false),
            "dr\xc3\xa9pe \xe2\x82\xac \xf0\x9f\x91\x97");
  const std::string replacement = "\xEF\xBF\xBD";
  EXPECT_EQ(xml_escaped(std::string("a\x01"
                                    "b",
                                    3),
                        false),
            "a" + replacement + "b");
  EXPECT_EQ(xml_escaped(std::string(1, '\0'), false), replacement);
  EXPECT_EQ(xml_escaped("\xc3", false), replacement);                    // truncated
  EXPECT_EQ(xml_escaped("\xc0\x80", false), replacement + replacement);  // overlong
  EXPECT_EQ(xml_escaped("\xed\xa0\x80", false),
            replacement + replacement + replacement);  // surrogate
  EXPECT_EQ(xml_escaped("\xef\xbf\xbe", false), replacement + replacement + replacement);  // U+FFFE
  EXPECT_EQ(xml_escaped("\x80x", false), replacement + "x");  // a stray continuation byte
  EXPECT_EQ(xml_escaped("\xe0\x80\x80", false),
            replacement + replacement + replacement);  // overlong
  EXPECT_EQ(xml_escaped("\xef\xbf\xbf", false), replacement + replacement + replacement);  // U+FFFF
  EXPECT_EQ(xml_escaped("\xf4\x90\x80\x80", false),
            replacement + replacement + replacement + replacement);       // past U+10FFFF
  EXPECT_EQ(xml_escaped("\xf4\x8f\xbf\xbd", false), "\xf4\x8f\xbf\xbd");  // U+10FFFD
}

}  // namespace
}  // namespace snag::report
