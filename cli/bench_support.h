// What the benchmarks share: medians, a scratch directory, the sample generator, the data folder.
#pragma once

#include <CLI/CLI.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "snag/detect/checker.h"
#include "snag/mesh/mesh.h"

namespace snag::cli {

/// Frames simulated before the timed ones, so that the cloth has landed on the sphere and folded
/// through itself: at the generator's default 30 frames per second, it folds from about frame
/// 15 and has thousands of intersecting pairs from frame 20 on (samples/README.md).
inline constexpr int settle_frames = 24;

double median(std::vector<double> v);

/// The checker a bench times: default settings on `backend` (make_backend), its exact stage's
/// loops on `threads` too, as snag check's are.
std::unique_ptr<detect::Checker> make_bench_checker(const std::string& backend, int threads,
                                                    int device);

/// A temporary directory removed with everything in it when the bench ends.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The sample generator: `given` (--generator) when set, else beside this executable (installed
/// layout), else in the build tree's samples/ (build layout), else `snag-cloth` on PATH.
std::string find_generator(const std::string& given);

/// How a child program ended.
struct ChildRun {
  bool started = false;  ///< false when it could not be run at all
  int exit_status = -1;  ///< -1 when it did not exit normally (a signal)
  double peak_mib = 0;   ///< its peak resident memory
};

/// Runs `args` (args[0] found on PATH when it has no '/') with its standard output thrown
/// away, and waits for it.
ChildRun run_quietly(const std::vector<std::string>& args);

/// Generates a cloth of about `triangles` triangles into `dir` with `settle` + `keep` frames and
/// returns the last `keep` frame files.
std::vector<std::filesystem::path> generated_cloth(const std::string& generator, int triangles,
                                                   int settle, int keep,
                                                   const std::filesystem::path& dir);

/// The shared data folder: `given` (--data), else $SNAG_DATA_DIR, else the one known at build
/// time; empty when none is known.
std::filesystem::path data_folder(const std::string& given);

/// One benchmark case: a name and its frame files, which share one topology.
struct BenchCase {
  std::string name;
  std::vector<std::filesystem::path> files;
};

/// A case of the frames of a sequence (a file, folder, pattern or glob, as `snag check` takes).
BenchCase sequence_case(std::string name, const std::string& sequence);

/// Appends the case `name` made of the shared data folder's `folder`, when it is there. When it
/// is not: a usage error if the user named the data folder (`given`), else a note on standard
/// error that the case is left out.
void add_data_case(std::vector<BenchCase>& cases, const std::filesystem::path& data,
                   const std::string& given, const std::string& name, const std::string& folder,
                   std::string_view command);

/// Where a benchmark's cases come from, as every `snag bench` command takes them.
struct CaseOptions {
  std::vector<int>* sizes;           ///< --sizes: generated cloth sizes
  std::string* data_dir;             ///< --data
  std::vector<std::string>* inputs;  ///< --input, repeatable
  std::string* generator;            ///< --generator
  int* threads;                      ///< -j, --threads
};

/// Adds --sizes (when wanted), --data, --input, --generator and -j/--threads to `cmd`. `data_cases`
/// says what the data folder contributes ("its cloth-ball frames are a case"); `verb` what is done
/// to an
/// --input sequence ("time", "score").
void add_case_options(CLI::App* cmd, const CaseOptions& o, const std::string& data_cases,
                      const std::string& verb);

/// A case's frames, read. Each file is read twice and the second read timed, so that the time
/// is snag's reader on a file in the page cache, not the disk. Throws InputError unless every
/// frame has the first one's vertex and triangle counts.
struct CaseFrames {
  std::vector<mesh::Mesh> meshes;
  std::vector<double> read_seconds;  ///< per frame
  std::vector<double> read_bytes;    ///< per frame: the file's size
};
CaseFrames read_case(const BenchCase& c, std::string_view command);

}  // namespace snag::cli
