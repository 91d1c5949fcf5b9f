// Writing the report files of `--out DIR`, each complete or not at all: every file is written
// to a hidden temporary name in DIR and renamed over its final name only when all of them were
// written, so a failure leaves no new file behind (and an earlier run's files untouched).
// ReportStream (stream.h) writes the reports of a run frame by frame with the same mechanism.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "snag/report/report.h"

namespace snag::report {

/// A report file or directory could not be created or written (exit status 3).
class WriteError : public std::runtime_error {
 public:
  WriteError(const std::filesystem::path& path, const std::string& what)
      : std::runtime_error(path.string() + ": " + what), path_(path) {}
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// One file to write: its name in the output directory and what writes its content.
struct OutputFile {
  std::string name;
  std::function<void(std::ostream&)> write;
};

/// Writes every file into `dir` (created if missing) under a temporary name, then renames
/// them all into place. Throws WriteError naming the path on failure, after removing every
/// temporary file it created.
void write_files_atomically(const std::filesystem::path& dir, const std::vector<OutputFile>& files);

/// Checks up front that `dir` is, or can be created as, a writable directory (so a long run
/// does not fail at its end); creates it. Throws WriteError otherwise.
void prepare_output_dir(const std::filesystem::path& dir);

/// The output directory of a run, made ready (prepare_output_dir), and those of it and its
/// parents that the run created: removed again while empty unless keep() is called (the run
/// failed), so that a failed run leaves nothing behind where there was nothing. (Not on a
/// signal: the handler removes the report temporaries only.) A path through ".." is made but
/// never removed: what it names is not what its spelling's prefixes name (a link, or "x/.."
/// made from nothing). Throws WriteError as prepare_output_dir does, having removed what it
/// made.
class OutputDirectory {
 public:
  explicit OutputDirectory(const std::filesystem::path& dir);
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;
  /// The run succeeded: the directory holds its reports.
  void keep() { created_.clear(); }

 private:
  void remove_created() noexcept;
  std::vector<std::filesystem::path> created_;  ///< deepest first
};

/// Removes every report temporary of this process that may be on disk (written, not yet
/// renamed into place or removed); finished reports are not touched. Async-signal-safe (atomic
/// loads and unlink): for a handler of SIGINT or SIGTERM, so that a run killed midway leaves no
/// hidden temporaries in its output directory, as a run that fails leaves none. For a process
/// that is ending: a temporary another thread creates after the call is removed at once.
void remove_temporaries_on_signal() noexcept;

/// Writes pairs.csv, frames.csv and report.json into `dir`, all complete or none, through a
/// ReportStream fed report.frames in increasing frame number (stable: the documented order of
/// Report::frames; a report recorded out of order gets its report.json frames sorted too,
/// unlike report_json, which keeps the record order).
void write_reports(const std::filesystem::path& dir, const Report& report);

}  // namespace snag::report
