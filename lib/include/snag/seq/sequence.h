// Animation sequences: which files make up SEQUENCE, their frame numbers, and --frames.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace snag::seq {

/// One frame of a sequence: its number (from the file name) and its file.
struct Frame {
  int64_t number = 0;
  std::filesystem::path path;
  bool operator==(const Frame&) const = default;
};

/// Resolves the SEQUENCE argument into its frames, sorted by frame number. In order:
/// - an existing file: one frame, numbered by the last run of digits in its stem (0 if none);
/// - an existing directory: its `.obj` and `.ply` files (any case; not recursive), each numbered
///   by the last run of digits in its stem;
/// - a pattern whose file name holds one frame token: `%d`, `%04d` (printf), `#`, `####`, `@`,
///   `@@@@` (one character per digit), Houdini's `$F` or `$F4`. The token matches what printf
///   would write for that width: a number with leading zeros matches only at exactly the width
///   (`%04d` matches `0007` and `12345`, not `007` or `00007`); an optional '-' for negative
///   frames. The frame number is the matched number;
/// - a glob whose file name has `*`, `?` or `[...]` (`[!...]` negates): matching files, each
///   numbered by the last run of digits in its stem.
/// Tokens and glob characters are understood in the last path component only.
/// Throws snag::InputError naming SEQUENCE when nothing exists or matches (for a pattern, naming
/// a file it would match at another width), when two files have the same frame number, or when
/// a directory or a glob gives several files and one has no digits in its name;
/// snag::UsageError for an empty argument or a pattern with more than one frame token.
std::vector<Frame> resolve_sequence(const std::string& sequence);

/// The last run of decimal digits in the file's stem, 0 when there is none
/// (`dress.0042.obj` -> 42, `cloth_ball92.ply` -> 92, `t0.ply` -> 0, `body.obj` -> 0).
/// Throws snag::InputError when the digits do not fit in 64 bits (a sequence of one file then
/// takes frame 0; the frames of a longer one need their numbers to be ordered).
int64_t frame_number_from_name(const std::filesystem::path& path);

/// A --frames selection: comma-separated items `N`, `FIRST-LAST` or `FIRST-LASTxSTEP` (every
/// STEP-th frame number counted from FIRST), inclusive; numbers may be negative (`-10--1`).
/// A default-constructed selection selects every frame.
class FrameSelection {
 public:
  FrameSelection() = default;

  /// Parses a selection; throws snag::UsageError quoting the bad item and the expected form.
  static FrameSelection parse(std::string_view text);

  bool contains(int64_t frame) const;
  bool selects_all() const { return all_; }
  /// The numbers this selection names that `frames` (in increasing number) lacks, as runs
  /// ("7", "20-30", "1-240x5"), each item's runs in order, at most `most_runs` of them; empty
  /// when every number named is a frame (or the selection selects all). `more`, when given, is
  /// set to whether more runs are absent than were returned.
  std::vector<std::string> absent_runs(const std::vector<Frame>& frames, size_t most_runs,
                                       bool* more = nullptr) const;
  const std::string& text() const { return text_; }

 private:
  struct Range {
    int64_t first, last, step;
  };
  std::vector<Range> ranges_;
  std::string text_;
  bool all_ = true;
};

/// The numbers a sequence lacks between its first frame and its last (FrameGaps::runs), on the
/// grid of the greatest common divisor of the differences between its numbers: a cache written
/// every 5th frame (1, 6, 11, ...) has no gaps, and one of frames 1, 2, 3, 5 lacks 4.
struct FrameGaps {
  int64_t first = 0, last = 0;  ///< the first and last frame numbers
  int64_t step = 0;             ///< the grid's step (0 when there are no runs to find)
  /// The missing numbers as runs ("4", "6-7", "10-30x5"), at most `most_runs` of them.
  std::vector<std::string> runs;
  bool more = false;  ///< more runs are missing than `runs` holds
};

/// The gaps of `frames` (in increasing number, each number once, as resolve_sequence returns
/// them). A sequence of fewer than three frames has none: two numbers make their own grid.
FrameGaps frame_gaps(const std::vector<Frame>& frames, size_t most_runs);

/// The frames of `frames` that `selection` contains, in the same order. Throws
/// snag::UsageError when the selection keeps none of a non-empty sequence.
std::vector<Frame> select_frames(const std::vector<Frame>& frames, const FrameSelection& selection);

}  // namespace snag::seq
