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
//
// A frame's rows and record are formatted by one of the stream's threads (up to write_ahead of
// them, each formatting a frame of its own), and written in the order the frames were added by
// whichever of them finds the next frame formatted. One thread keeps up with a CPU check; a
// GPU checks a 3K-pair frame faster than one thread formats its ~280 KB of text (and writing
// them, one thread's copy into the page cache, is most of what is left to the stream: a pair is
// ~30 bytes of pairs.csv and ~60 of report.json, see append_pairs_array in json.cpp).
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
  ///
  /// `formatters`: threads that format frames side by side (1 to write_ahead; clamped). They
  /// take CPU time only while frames wait to be formatted.
  ReportStream(std::optional<std::filesystem::path> dir, std::string snag_version,
               Settings settings, std::vector<ObjectInput> objects = {}, int formatters = 1);
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
  /// The rows are formatted and written by the stream's own threads, so that a frame with
  /// millions of pairs does not hold up the check of the next: add() hands the record over
  /// and returns, waiting only while write_ahead frames are still unwritten. A failed write
  /// throws WriteError from the next add() or from finish().
  void add(FrameRecord frame);

  /// Frames handed over and not yet written, at most: what the memory bound is counted in.
  static constexpr size_t write_ahead = 4;

  /// The summary of the frames added so far (worst_frame counts them in the order added).
  const Summary& summary() const;

  /// CPU seconds the stream's threads used formatting and writing the reports (the kernel's
  /// copies into the page cache included), once finish() has returned; 0 before, and without
  /// an output directory.
  double cpu_seconds() const { return cpu_seconds_; }

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

  /// A frame handed over: its record, then its pairs.csv rows and report.json element as its
  /// formatter made them. `sequence` counts the frames handed over from 0.
  struct Unwritten {
    FrameRecord frame;
    uint64_t sequence = 0;
    bool formatted = false;
    std::string pairs_text, json_text;
  };

  /// A formatter thread: takes the next frame not yet taken, formats it, then writes what is
  /// ready (write_ready).
  void format_loop();
  /// With the lock held: writes the formatted frames at the front of the queue, in order,
  /// unless another thread is writing (it will find them when its write is done).
  void write_ready(std::unique_lock<std::mutex>& lock);
  void write_frame(Unwritten& frame);
  /// Waits until every frame handed over is written, then stops the formatter threads. Returns
  /// their error, if a write failed.
  std::exception_ptr stop_writer();

  Report run_;                        ///< report.json's head and totals; its frames stay empty
  std::vector<ObjectInput> objects_;  ///< the constructor's: the names of rows and records
  bool baseline_ = false;  ///< settings.baseline given: the reports' accepted columns and members
  SummaryAccumulator accumulator_;
  std::optional<int64_t> last_frame_;
  std::unique_ptr<Files> files_;
  bool finished_ = false;

  // The formatter threads and the frames handed to them (only with an output directory). A
  // frame's texts (~450 KB of report.json for 3K pairs) are each written at once; their buffers
  // go back to `spare_texts_` rather than being allocated for every frame.
  std::mutex mutex_;
  std::condition_variable handed_over_, written_;
  std::deque<Unwritten> unwritten_;  ///< in sequence order; references stay valid at its ends
  uint64_t handed_ = 0;              ///< frames handed over
  uint64_t taken_ = 0;               ///< frames taken by a formatter (the next one's sequence)
  bool writing_ = false;             ///< a thread is in write_ready's loop
  std::vector<std::string> spare_texts_;
  bool closing_ = false;
  std::exception_ptr write_error_;
  std::vector<std::thread> formatters_;
  double cpu_seconds_ = 0;  ///< each formatter thread's CPU time, added as it ends
};

}  // namespace snag::report
