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
// whichever of them finds the next frame formatted: its pairs.csv, frames.csv and file-name
// part by one thread while its report.json part may be written by another (each part's frames
// in order). One thread keeps up with a CPU check; a GPU checks a 3K-pair frame faster than one
// thread formats its ~280 KB of text (a pair is ~30 bytes of pairs.csv and ~60 of report.json,
// see append_pairs_array in json.cpp), and copying the text into the page cache is as much
// again. On the H100's 16-core host, 1,000 frames of 2,274 pairs through the stream alone took
// 0.100 ms a frame with 4 formatters and one writer, 0.084 with 8 and one, 0.063 with 8 and a
// writer per part (medians of three runs, 0.095-0.118 with 4 and two).
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
  static constexpr size_t write_ahead = 8;

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

  /// A frame handed over: its record, then its pairs.csv rows and report.json element as its
  /// formatter made them. `sequence` counts the frames handed over from 0.
  struct Unwritten {
    FrameRecord frame;
    uint64_t sequence = 0;
    bool formatted = false;
    std::string pairs_text, json_text;
  };

  /// What a frame writes, in two parts that go to different files and can be written side by
  /// side by two threads (each part's frames in order): its pairs.csv rows, frames.csv row and
  /// file name; its report.json element. Copying a frame's text into the page cache is most of
  /// the stream's time, and report.json is two thirds of the bytes.
  enum Part { csv_part = 0, json_part = 1 };

  /// A formatter thread: takes the next frame not yet taken, formats it, then writes what is
  /// ready (write_ready).
  void format_loop();
  /// With the lock held: for each part not being written by another thread, writes that part
  /// of the formatted frames whose turn it is, in order, and drops the frames written whole
  /// from the front of the queue; returns when neither part has a frame ready for it (another
  /// thread writing one finds the frames formatted meanwhile when its write is done).
  void write_ready(std::unique_lock<std::mutex>& lock);
  void write_part(Unwritten& frame, Part part);
  /// Waits until every frame handed over is written, then stops the formatter threads. Returns
  /// their error, if a write failed.
  std::exception_ptr stop_writer();

  Report run_;                        ///< report.json's head and totals; its frames stay empty
  std::vector<ObjectInput> objects_;  ///< the constructor's: the names of rows and records
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
  bool writing_[2] = {false, false};  ///< per Part: a thread is writing that part
  uint64_t parts_written_[2] = {0, 0};  ///< per Part: how many frames have that part written
  std::vector<std::string> spare_texts_;
  bool closing_ = false;
  std::exception_ptr write_error_;
  std::vector<std::thread> formatters_;
};

}  // namespace snag::report
