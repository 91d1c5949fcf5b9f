// The reports of a run written as its frames finish: pairs.csv, frames.csv and report.json
// appear all at once at the end, complete, or not at all, while memory stays bounded however
// long the sequence is.
//
// Each frame's rows are appended, by the stream's writer thread soon after the frame is
// added, to hidden temporaries in the output directory: its pairs.csv rows and frames.csv row to
// the temporaries that become those files, its report.json record and file name to two scratch
// spools. finish() writes report.json as its head (schema, version, settings, inputs with the
// spooled file names), the spooled frame records and the summary, then renames the three files into
// place. What the stream holds is a fixed amount: the settings, the summary accumulator (counts,
// and the worst frame's number, file and counts), the stream buffers and at most write_ahead frames
// not yet written.
//
// The bytes are those of write_pairs_csv, write_frames_csv and report_json for the same frames
// (one formatter per row and record serves both: csv.h, json.cpp).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "snag/report/report.h"

namespace snag::report {

class ReportStream {
 public:
  /// `dir`: where the reports go (created if missing; its temporaries are created here, so an
  /// unusable directory throws WriteError before the first frame); nullopt keeps only the
  /// summary. `snag_version` and `settings` are report.json's head; settings.fail_on decides
  /// Summary::failed.
  ///
  /// `objects`: a scene run's objects (Inputs::objects), empty for a single mesh. Known up
  /// front because they choose the CSV headers, written here, and name the objects in every
  /// row and frame record; only their names are used before finish(), whose inputs.objects
  /// (with the first frame's counts, say) must name the same objects in the same order.
  ReportStream(std::optional<std::filesystem::path> dir, std::string snag_version,
               Settings settings, std::vector<ObjectInput> objects = {});
  /// Without a successful finish() (an exception unwinding the run, say), removes every
  /// temporary: no report file appears, and an earlier run's files stay as they were.
  ~ReportStream();
  ReportStream(const ReportStream&) = delete;
  ReportStream& operator=(const ReportStream&) = delete;

  /// Appends a checked frame's rows. Frames must come in non-decreasing frame number (the
  /// order of checking, which the CSV files promise); an earlier number throws InternalError.
  /// `frame.pairs` in any order (the CSV sorts them by pair_order, report.json keeps the
  /// record's order, as the whole-report writers do). In a scene run every object index in the
  /// record must be one of the constructor's objects and frame.objects has one entry per
  /// object, else the write fails with InternalError (from a later add() or finish()).
  ///
  /// The rows are formatted and written by the stream's own thread, so that a frame with
  /// millions of pairs does not hold up the check of the next: add() hands the record over
  /// and returns, waiting only while write_ahead frames are still unwritten. A failed write
  /// throws WriteError from the next add() or from finish().
  void add(FrameRecord frame);

  /// Frames handed over and not yet written, at most: what the memory bound is counted in.
  static constexpr size_t write_ahead = 4;

  /// The summary of the frames added so far (worst_frame counts them in the order added).
  const Summary& summary() const;

  /// Ends the run with what is known only at its end: `inputs` (inputs.sequence, ids and the
  /// first frame's vertex counts; the files are the frames added; inputs.objects, the scene's
  /// objects as report.json lists them), the tree builds and rebuilds, and the run's
  /// wall-clock seconds. Writes report.json, then renames the three files into place (see
  /// StagedFiles::commit). Returns the final summary. Throws WriteError; InternalError when
  /// inputs.objects do not have the constructor's names in its order. After a throw no new
  /// report file is in place and no temporary is left. Call once.
  Summary finish(const Inputs& inputs, int builds, int rebuilds, double wall_seconds);

 private:
  struct Files;  // the temporaries, absent without an output directory

  void write_loop();
  void write_frame(const FrameRecord& frame, bool first);
  /// Waits until every frame handed over is written, then stops the writer thread. Returns
  /// its error, if a write failed.
  std::exception_ptr stop_writer();

  Report run_;                        ///< report.json's head and totals; its frames stay empty
  std::vector<ObjectInput> objects_;  ///< the constructor's: the names of rows and records
  SummaryAccumulator accumulator_;
  std::optional<int64_t> last_frame_;
  std::unique_ptr<Files> files_;
  /// The writer thread's text of a frame's rows, then of its record (~450 KB of report.json for
  /// 3K pairs), each written at once; kept from frame to frame rather than allocated for each.
  std::string text_;
  bool finished_ = false;

  // The writer thread and the frames handed to it (only with an output directory).
  std::mutex mutex_;
  std::condition_variable handed_over_, written_;
  std::deque<FrameRecord> unwritten_;
  bool closing_ = false;
  std::exception_ptr write_error_;
  std::thread writer_;
};

}  // namespace snag::report
