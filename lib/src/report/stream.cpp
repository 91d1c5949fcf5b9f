#include "snag/report/stream.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <utility>
#include <vector>

#include "json_layout.h"
#include "snag/cpu_time.h"
#include "snag/error.h"
#include "snag/report/csv.h"
#include "snag/report/write.h"
#include "staged_files.h"

namespace snag::report {

namespace fs = std::filesystem;

namespace {

/// Appends the scratch file `piece` to `out` in fixed-size chunks: a spool holds the whole
/// run's records and is never read into memory at once.
void append_scratch(const StagedFile& piece, std::ostream& out) {
  std::ifstream in(piece.temporary_path(), std::ios::binary);
  if (!in)
    throw WriteError(piece.final_path(), std::string("cannot read back its temporary ") +
                                             piece.temporary_path().filename().string() + ": " +
                                             std::strerror(errno));
  std::vector<char> chunk(1 << 16);
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0)
    out.write(chunk.data(), in.gcount());
  if (in.bad())
    throw WriteError(piece.final_path(),
                     "read failed on its temporary " + piece.temporary_path().filename().string());
}

/// With `lock` held: runs `work` with it released, unless a write failed already (the run is
/// lost then, and the rest is dropped), and keeps the first error in `first_error`.
template <class Work>
void unlocked_unless_failed(std::unique_lock<std::mutex>& lock, std::exception_ptr& first_error,
                            Work&& work) {
  const bool failed = first_error != nullptr;
  lock.unlock();
  std::exception_ptr error;
  if (!failed) {
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
  }
  lock.lock();
  if (error && !first_error) first_error = error;
}

}  // namespace

/// The three reports' temporaries and report.json's spool of file names. The reports are created
/// first, in the order write_reports has always renamed them.
struct ReportStream::Files {
  explicit Files(const fs::path& dir)
      : staged(dir),
        pairs_csv(staged.create("pairs.csv")),
        frames_csv(staged.create("frames.csv")),
        report_json(staged.create("report.json")),
        file_names(staged.create_scratch("report.json", "files")) {}

  StagedFiles staged;
  StagedFile& pairs_csv;
  StagedFile& frames_csv;
  StagedFile& report_json;  ///< its head, then frames elements as frames are added (the run's
                            ///< bulk, never copied again), the rest by finish()
  StagedFile& file_names;   ///< inputs.files elements, one per frame added
};

ReportStream::ReportStream(std::optional<fs::path> dir, std::string snag_version, Settings settings,
                           std::vector<ObjectInput> objects, int formatters)
    : objects_(std::move(objects)),
      baseline_(settings.baseline.has_value()),
      accumulator_(settings.fail_on) {
  run_.snag_version = std::move(snag_version);
  run_.settings = std::move(settings);
  if (!dir) return;
  files_ = std::make_unique<Files>(*dir);
  files_->pairs_csv.out() << pairs_csv_header_for(objects_, baseline_) << '\n';
  files_->frames_csv.out() << frames_csv_header_for(objects_, baseline_) << '\n';
  write_report_json_head(files_->report_json.out(), run_);
  const int threads = std::clamp(formatters, 1, static_cast<int>(write_ahead));
  try {
    for (int i = 0; i < threads; ++i) formatters_.emplace_back([this] { format_loop(); });
  } catch (...) {
    stop_writer();  // the threads started: a joinable thread left to its destructor terminates
    throw;
  }
}

// files_'s StagedFiles then removes what was not renamed.
ReportStream::~ReportStream() {
  stop_writer();
}

void ReportStream::format_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    handed_over_.wait(lock, [&] { return closing_ || taken_ < handed_; });
    if (taken_ == handed_) {  // closing, every frame taken
      cpu_seconds_ += thread_cpu_seconds();
      return;
    }
    // References into the deque stay valid while others are added or written: this frame
    // is neither written nor moved before it is marked formatted.
    Unwritten& entry = unwritten_[taken_ - unwritten_.front().sequence];
    ++taken_;
    for (std::string* text : {&entry.pairs_text, &entry.json_text}) {
      if (spare_texts_.empty()) break;
      *text = std::move(spare_texts_.back());
      spare_texts_.pop_back();
    }
    unlocked_unless_failed(lock, write_error_, [&] {
      append_pairs_rows(entry.pairs_text, entry.frame, objects_, baseline_);
      append_json_frame_element(entry.json_text, entry.frame, entry.sequence == 0, objects_,
                                baseline_);
    });
    entry.formatted = true;
    write_ready(lock);
  }
}

void ReportStream::write_ready(std::unique_lock<std::mutex>& lock) {
  if (writing_) return;
  writing_ = true;
  while (!unwritten_.empty() && unwritten_.front().formatted) {
    // The frame stays in the queue while it is written: add() counts it as unwritten.
    Unwritten& entry = unwritten_.front();
    unlocked_unless_failed(lock, write_error_, [&] { write_frame(entry); });
    for (std::string* text : {&entry.pairs_text, &entry.json_text}) {
      text->clear();  // its capacity stays for a later frame
      spare_texts_.push_back(std::move(*text));
    }
    unwritten_.pop_front();
    written_.notify_all();
  }
  writing_ = false;
}

void ReportStream::write_frame(Unwritten& entry) {
  const auto write = [&](StagedFile& file, const std::string& text) {
    file.out().write(text.data(), static_cast<std::streamsize>(text.size()));
  };
  write(files_->pairs_csv, entry.pairs_text);
  write_frames_row(files_->frames_csv.out(), entry.frame, objects_, baseline_);
  files_->file_names.out() << json_file_element(entry.frame.file, entry.sequence == 0);
  write(files_->report_json, entry.json_text);
  for (const StagedFile* f :
       {&files_->pairs_csv, &files_->frames_csv, &files_->file_names, &files_->report_json})
    f->check();
}

std::exception_ptr ReportStream::stop_writer() {
  if (formatters_.empty()) return write_error_;
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
  }
  handed_over_.notify_all();
  // The last formatter to mark its frame formatted writes every frame left (write_ready).
  for (std::thread& formatter : formatters_) formatter.join();
  formatters_.clear();
  return write_error_;
}

const Summary& ReportStream::summary() const {
  return accumulator_.summary();
}

void ReportStream::add(FrameRecord frame) {
  if (finished_)
    throw InternalError("report: frame " + std::to_string(frame.frame) +
                        " added after the report was finished");
  if (last_frame_ && frame.frame < *last_frame_)
    throw InternalError("report: frame " + std::to_string(frame.frame) + " added after frame " +
                        std::to_string(*last_frame_) +
                        "; frames must come in increasing frame number");
  accumulator_.add(frame);
  last_frame_ = frame.frame;
  if (!files_) return;
  {
    std::unique_lock lock(mutex_);
    written_.wait(lock, [&] { return unwritten_.size() < write_ahead || write_error_; });
    if (write_error_) std::rethrow_exception(write_error_);
    unwritten_.push_back({std::move(frame), handed_++, false, {}, {}});
  }
  handed_over_.notify_one();
}

Summary ReportStream::finish(const Inputs& inputs, int builds, int rebuilds, double wall_seconds) {
  if (finished_) throw InternalError("report: finished twice");
  finished_ = true;
  const bool same_objects =
      std::equal(inputs.objects.begin(), inputs.objects.end(), objects_.begin(), objects_.end(),
                 [](const ObjectInput& x, const ObjectInput& y) { return x.name == y.name; });
  if (!same_objects)
    throw InternalError("report: finished with " + std::to_string(inputs.objects.size()) +
                        " objects; the stream was made with " + std::to_string(objects_.size()) +
                        " (names and order must match)");
  run_.inputs = inputs;
  run_.builds = builds;
  run_.rebuilds = rebuilds;
  run_.wall_seconds = wall_seconds;
  const Summary summary = accumulator_.summary();
  if (files_) {
    if (const std::exception_ptr error = stop_writer()) std::rethrow_exception(error);
    // The spool is closed (flushed, checked) before it is read back.
    files_->file_names.close();
    write_report_json_tail(files_->report_json.out(), run_, summary,
                           [&](std::ostream& out) { append_scratch(files_->file_names, out); });
    files_->staged.commit();
    files_.reset();
  }
  return summary;
}

}  // namespace snag::report
