// Progress of a run on standard error: a bar redrawn in place when standard error is a
// terminal, one line per frame otherwise (logs of CI jobs), nothing with --quiet.
#pragma once

#include <cstdint>
#include <string>

namespace snag::cli {

class Progress {
 public:
  Progress(int64_t total, bool quiet);
  ~Progress();
  /// Frame `done` of `total` finished; `note` says what it found.
  void update(int64_t done, const std::string& note);
  /// Removes the bar (before anything else is printed), if one is drawn.
  void finish();
  /// Prints a message line without breaking the bar.
  void message(const std::string& line);

 private:
  int64_t total_;
  bool quiet_;
  bool bar_;
  bool drawn_ = false;
};

}  // namespace snag::cli
