// Files written under hidden temporary names in their final directory and renamed over their
// final names together: the one mechanism behind write_files_atomically, ReportStream and
// prepare_output_dir. Private to snag::lib.
//
// A temporary is `DIR/.NAME.tmp-PID-N` (scratch pieces `DIR/.NAME.PART.tmp-PID-N`): in the same
// directory because rename is atomic only within one filesystem, hidden so that a directory
// listing shows only finished reports, unique per process and file so that two runs writing
// into one directory never share a temporary.
#pragma once

#include <filesystem>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace snag::report {

/// `dir / ".NAME.tmp-PID-N"`, N counting up per process.
std::filesystem::path temporary_name(const std::filesystem::path& dir, const std::string& name);

/// Removes `path` if it exists, ignoring errors: used on the way out of a failure, where the
/// first error is the one to report.
void remove_quietly(const std::filesystem::path& path);

/// Creates `dir` and its parents if missing. Throws WriteError when it exists and is not a
/// directory or cannot be created.
void ensure_directory(const std::filesystem::path& dir);

/// Makes a temporary that is not part of a StagedFiles set (prepare_output_dir's probe) known
/// to remove_temporaries_on_signal while it lives: construct it before creating the file, call
/// created() once the file exists, and remove the file before it is destroyed.
class SignalTracked {
 public:
  explicit SignalTracked(const std::filesystem::path& temporary_path);
  ~SignalTracked();
  SignalTracked(const SignalTracked&) = delete;
  SignalTracked& operator=(const SignalTracked&) = delete;
  void created();

 private:
  int slot_;
};

/// One temporary file being written.
class StagedFile {
 public:
  StagedFile(std::filesystem::path temporary_path, std::filesystem::path final_path);
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  std::ostream& out() { return out_; }
  const std::filesystem::path& temporary_path() const { return temporary_path_; }
  /// The name errors give: the report the user asked for, not its hidden temporary.
  const std::filesystem::path& final_path() const { return final_path_; }

  /// Throws WriteError naming final_path() when a write has failed so far. Data still in the
  /// stream's buffer has not met the disk yet: close() reports what fails there.
  void check() const;
  /// Flushes and closes; throws WriteError when a write failed (a full disk shows up at the
  /// flush, not at the first write). Closing twice is harmless.
  void close();

 private:
  std::filesystem::path temporary_path_;
  std::filesystem::path final_path_;
  std::ofstream out_;
};

/// The temporaries of one output directory. Files made by create() are renamed into place by
/// commit(), in creation order; scratch files (pieces read back to compose another file) are
/// never renamed. Whatever is still on disk under a temporary name when the set is destroyed
/// is removed, so a run that throws, or never commits, leaves no temporary and no new file.
class StagedFiles {
 public:
  /// Creates `dir` if missing (WriteError when it cannot be, or is not a directory).
  explicit StagedFiles(std::filesystem::path dir);
  ~StagedFiles();
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;

  /// A temporary that commit() renames to `dir / name`. The reference stays valid for the
  /// set's lifetime. Throws WriteError naming `dir / name` when it cannot be created, or when a
  /// directory holds that name (which no rename could replace).
  StagedFile& create(const std::string& name);
  /// A temporary that holds a piece `part` of the file `name` while it is being composed
  /// (errors name `dir / name`); removed by commit() and never renamed.
  StagedFile& create_scratch(const std::string& name, const std::string& part);

  /// Closes every file (WriteError when a write failed, then nothing is renamed), removes the
  /// scratch files and renames the others into place, after checking that no directory has
  /// taken a final name since create() (WriteError, nothing renamed). The renames are the only
  /// step that replaces an earlier run's files; each is atomic, and only an error between two
  /// of them (the directory removed or made read-only meanwhile) could leave some renamed and
  /// others not. Commit at most once.
  void commit();

 private:
  struct Entry {
    std::filesystem::path temporary_path;  ///< what the destructor removes
    std::unique_ptr<StagedFile> file;      ///< unique_ptr: references stay valid as the set grows
    bool scratch = false;
    int tracked_slot = -1;  ///< for remove_temporaries_on_signal, while the file may exist
  };
  StagedFile& open(std::filesystem::path temporary_path, const std::string& name, bool scratch);

  std::filesystem::path dir_;
  std::vector<Entry> entries_;  ///< in creation order
  bool committed_ = false;
};

}  // namespace snag::report
