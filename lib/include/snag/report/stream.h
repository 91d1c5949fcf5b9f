// The reports of a run written as its frames finish: pairs.csv, frames.csv and report.json
// appear all at once at the end, complete, or not at all, while memory stays bounded however
// long the sequence is.
//
// Each frame's rows are appended, as the frame is added, to hidden temporaries in the output
// directory: its pairs.csv rows and frames.csv row to the temporaries that become those files,
// its report.json record and file name to two scratch spools. finish() writes report.json as
// its head (schema, version, settings, inputs with the spooled file names), the spooled frame
// records and the summary, then renames the three files into place. What the stream holds is
// a fixed amount: the settings, the summary accumulator (counts, and the worst frame's number,
// file and counts) and the stream buffers; the caller can drop each frame once it is added.
//
// The bytes are those of write_pairs_csv, write_frames_csv and report_json for the same frames
// (one formatter per row and record serves both: csv.h, json.cpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "snag/report/report.h"

namespace snag::report {

class ReportStream {
 public:
  /// `dir`: where the reports go (created if missing; its temporaries are created here, so an
  /// unusable directory throws WriteError before the first frame); nullopt keeps only the
  /// summary. `snag_version` and `settings` are report.json's head; settings.fail_on decides
  /// Summary::failed.
  ReportStream(std::optional<std::filesystem::path> dir, std::string snag_version,
               Settings settings);
  /// Without a successful finish() (an exception unwinding the run, say), removes every
  /// temporary: no report file appears, and an earlier run's files stay as they were.
  ~ReportStream();
  ReportStream(const ReportStream&) = delete;
  ReportStream& operator=(const ReportStream&) = delete;

  /// Appends a checked frame's rows. Frames must come in non-decreasing frame number (the
  /// order of checking, which the CSV files promise); an earlier number throws InternalError.
  /// `frame.pairs` in any order (the CSV sorts them by (a, b), report.json keeps the record's
  /// order, as the whole-report writers do). Throws WriteError when a write fails.
  void add(const FrameRecord& frame);

  /// The summary of the frames added so far (worst_frame counts them in the order added).
  const Summary& summary() const;

  /// Ends the run with what is known only at its end: `inputs` (inputs.sequence, ids and the
  /// first frame's vertex counts; the files are the frames added), the tree builds and
  /// rebuilds, and the run's wall-clock seconds. Writes report.json, then renames the three
  /// files into place (see StagedFiles::commit). Returns the final summary. Throws WriteError;
  /// after a throw no new report file is in place and no temporary is left. Call once.
  Summary finish(const Inputs& inputs, int builds, int rebuilds, double wall_seconds);

 private:
  struct Files;  // the temporaries, absent without an output directory

  Report run_;  ///< report.json's head and totals; its frames stay empty
  SummaryAccumulator accumulator_;
  std::optional<int64_t> last_frame_;
  std::unique_ptr<Files> files_;
  bool finished_ = false;
};

}  // namespace snag::report
