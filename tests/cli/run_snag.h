// Running the built `snag` in a child process, and small file helpers for the CLI tests.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace snag::test {

/// $SNAG_EXECUTABLE, else the executable CMake built.
std::filesystem::path snag_executable();

struct RunResult {
  int status = -1;  ///< exit status; 128 + signal when killed by one
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

/// Runs snag with `args` in working directory `cwd`, standard input closed, and waits for it.
RunResult run_snag(const std::vector<std::string>& args, const std::filesystem::path& cwd);

/// Runs snag with `args` in `cwd` on a pseudo-terminal `columns` wide (standard input, output and
/// error all on it, as in an interactive shell); `out` holds everything it wrote there, `err`
/// nothing. nullopt when no pseudo-terminal can be opened here (a container without /dev/pts).
std::optional<RunResult> run_snag_in_terminal(const std::vector<std::string>& args,
                                              const std::filesystem::path& cwd, int columns);

/// run_snag with $SNAG_DATA_DIR an empty folder (cwd/no-data), so that a bench leaves out its
/// shared-data cases; $SNAG_DATA_DIR is as it was afterwards.
RunResult run_snag_without_data(const std::vector<std::string>& args,
                                const std::filesystem::path& cwd);

/// Sets (or, with nullptr, unsets) an environment variable for its lifetime, then puts back what
/// was there, also when a test fails or throws in between.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value);
  ~ScopedEnv();
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> previous_;
};

/// The whitespace-separated words after `prefix` of the `nth` line (from 0) of `text` that
/// starts with it (a row of a bench table); a test failure and no words when there is none.
std::vector<std::string> table_row(const std::string& text, const std::string& prefix, int nth = 0);

/// A fresh directory under the system temporary directory, removed with its contents.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

std::string read_text(const std::filesystem::path& path);
void write_text(const std::filesystem::path& path, const std::string& text);

/// Rows of a CSV file without quoted fields (what snag writes for these samples), split on
/// commas; the header is row 0.
std::vector<std::vector<std::string>> parse_csv(const std::string& text);

/// Names in `dir`, sorted.
std::vector<std::string> directory_entries(const std::filesystem::path& dir);

}  // namespace snag::test
