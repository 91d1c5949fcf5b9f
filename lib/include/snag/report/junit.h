// A JUnit XML report of a run (`snag check --junit FILE`): what CI servers (Jenkins, GitLab,
// GitHub's test reporters) show as test results, so that a gate's failing frames appear in the
// job's page rather than only in its log and artifacts. One test case per checked frame, in
// checking order, named by its frame number and file; a frame that fails the run under
// --fail-on (a crossing pair, or with `any` a pair, that the baseline does not accept) is a
// failure whose text lists those pairs as pairs.csv rows (the first kListedPairs of them).
//
//   <?xml version="1.0" encoding="UTF-8"?>
//   <testsuites name="snag check" tests="12" failures="3" time="0.013204">
//     <testsuite name="SEQUENCE" tests="12" failures="3" skipped="0" errors="0"
//                time="0.013204">
//       <testcase classname="snag.check" name="frame 5: samples/drape/drape.0005.obj"
//                 time="0.000796">
//         <failure type="crossing" message="81 crossing pairs (--fail-on crossing)">
//   frame,face_a,face_b,kind,poly_a,poly_b[,object_a,object_b]
//   5,238,478,crossing,238,478
//   ...</failure>
//       </testcase>
//       ...
//
// Times are the frames' checking seconds (frames.csv's `seconds`), 6 decimals; a scene run's
// frames are named by their first object's file. Text is escaped for XML;
// bytes that XML 1.0 cannot hold (control characters, invalid UTF-8 in a file name) become
// U+FFFD.
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "snag/report/report.h"

namespace snag::report {

class JunitReport {
 public:
  /// Failing pairs listed in a failure's text; the rest are counted.
  static constexpr size_t kListedPairs = 50;

  /// `suite`: the suite's name (the SEQUENCE or scene file as given); `objects`: the run's
  /// Inputs::objects (empty for a single mesh), whose names the listed pairs carry.
  JunitReport(std::string suite, FailOn fail_on, std::vector<ObjectInput> objects = {});

  /// Keeps what `frame`'s test case needs: its number, file and time, and if it fails, its
  /// failure's message and text (at most kListedPairs pairs), not the frame.
  void add(const FrameRecord& frame);

  /// The whole document.
  void write(std::ostream& out) const;

 private:
  struct Case {
    int64_t frame = 0;
    std::string file;
    double seconds = 0;
    bool failed = false;
    std::string message;  ///< failure: its count of failing pairs
    std::string text;     ///< failure: the pairs, as CSV rows
  };
  std::string suite_;
  FailOn fail_on_;
  std::vector<ObjectInput> objects_;
  std::vector<Case> cases_;
};

/// `text` escaped for XML (&, <, >, " and '; a carriage return as a reference, and in an
/// `attribute` value a tab and a line feed too, which a parser would turn into spaces), with
/// every byte or sequence XML 1.0 cannot hold (control characters but tab, line feed and
/// carriage return; invalid UTF-8) replaced by U+FFFD.
std::string xml_escaped(std::string_view text, bool attribute);

}  // namespace snag::report
