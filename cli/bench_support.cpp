#include "bench_support.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <random>

#include "backend_factory.h"
#include "commands.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/seq/sequence.h"
#include "snag/validators/exact_modes.h"

extern char** environ;

namespace snag::cli {

namespace fs = std::filesystem;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::unique_ptr<detect::Checker> make_bench_checker(const std::string& backend, int threads,
                                                    int device) {
  detect::CheckSettings settings;
  settings.threads = threads;
  return validators::make_checker(make_backend(backend, threads, device), settings);
}

ScratchDir::ScratchDir() {
  std::random_device rd;
  path_ = fs::temp_directory_path() /
          ("snag-bench-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

std::string find_generator(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& candidate : {self.parent_path() / "snag-cloth",
                                      self.parent_path().parent_path() / "samples" / "snag-cloth"})
      if (fs::exists(candidate, ec)) return candidate.string();
  }
  return "snag-cloth";
}

ChildRun run_quietly(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  // A child's own summary would break up the table: its standard output goes nowhere.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ChildRun run;
  if (spawned != 0) return run;
  run.started = true;
  int status = 0;
  struct rusage usage {};
  if (::wait4(pid, &status, 0, &usage) < 0) return run;
  if (WIFEXITED(status)) run.exit_status = WEXITSTATUS(status);
  run.peak_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
  return run;
}

std::vector<fs::path> generated_cloth(const std::string& generator, int triangles, int settle,
                                      int keep, const fs::path& dir) {
  keep = std::max(1, keep);
  const int total = settle + keep;
  std::cerr << "snag bench: generating cloth, about " << triangles << " triangles, " << total
            << " frames\n";
  const std::string program = find_generator(generator);
  const ChildRun run = run_quietly({program, "--triangles", std::to_string(triangles), "--frames",
                                    std::to_string(total), "--output-dir", dir.string(), "--prefix",
                                    "cloth", "--quiet"});
  if (!run.started)
    throw UsageError("cannot run the sample generator '" + program +
                     "' (build it, or give its path with --generator)");
  if (run.exit_status != 0)
    throw InternalError("the sample generator '" + program + "' failed (" +
                        (run.exit_status < 0 ? std::string("killed by a signal")
                                             : "exit status " + std::to_string(run.exit_status)) +
                        ")");
  std::vector<fs::path> files;
  for (const seq::Frame& f : seq::resolve_sequence(dir.string())) files.push_back(f.path);
  if (files.size() > static_cast<size_t>(keep)) files.erase(files.begin(), files.end() - keep);
  return files;
}

fs::path data_folder(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv("SNAG_DATA_DIR"); env && *env) return env;
#ifdef SNAG_DATA_DIR_DEFAULT
  return SNAG_DATA_DIR_DEFAULT;
#else
  return {};
#endif
}

BenchCase sequence_case(std::string name, const std::string& sequence) {
  BenchCase c{std::move(name), {}};
  for (const seq::Frame& f : seq::resolve_sequence(sequence)) c.files.push_back(f.path);
  return c;
}

void add_data_case(std::vector<BenchCase>& cases, const std::filesystem::path& data,
                   const std::string& given, const std::string& name, const std::string& folder,
                   std::string_view command) {
  const std::filesystem::path dir = data / folder;
  if (!data.empty() && std::filesystem::is_directory(dir)) {
    cases.push_back(sequence_case(name, dir.string()));
  } else if (!given.empty()) {
    throw UsageError("--data " + given + ": no " + folder + " folder in it");
  } else {
    std::cerr << command << ": no "
              << (data.empty() ? std::string("shared data folder") : dir.string()) << "; the "
              << name << " case is left out\n";
  }
}

CaseFrames read_case(const BenchCase& c, std::string_view command) {
  using Clock = std::chrono::steady_clock;
  std::cerr << command << ": " << c.name << ": reading " << c.files.size() << " frames\n";
  CaseFrames frames;
  for (const std::filesystem::path& f : c.files) {
    io::read_mesh(f);
    const auto started = Clock::now();
    frames.meshes.push_back(io::read_mesh(f));
    frames.read_seconds.push_back(std::chrono::duration<double>(Clock::now() - started).count());
    frames.read_bytes.push_back(static_cast<double>(std::filesystem::file_size(f)));
  }
  if (frames.meshes.empty()) throw InputError(c.name, 0, "no frames");
  const mesh::Mesh& first = frames.meshes.front();
  for (const mesh::Mesh& m : frames.meshes)
    if (m.positions.size() != first.positions.size() ||
        m.triangles.size() != first.triangles.size())
      throw InputError(c.name, 0, "frames of a benchmark case must share one topology");
  return frames;
}

void add_case_options(CLI::App* cmd, const CaseOptions& o, const std::string& data_cases,
                      const std::string& verb) {
  if (o.sizes)
    cmd->add_option("--sizes", *o.sizes,
                    "Generated cloth sizes in triangles (0 or an empty list: none)")
        ->type_name("T,...")
        ->delimiter(',')
        ->check(kCount)
        ->capture_default_str();
  cmd->add_option("--data", *o.data_dir,
                  "The shared data folder; " + data_cases +
                      " when present (default: $SNAG_DATA_DIR, else the one known at build time)")
      ->type_name("DIR");
  cmd->add_option("--input", *o.inputs, "Also " + verb + " this sequence (repeatable)")
      ->type_name("SEQUENCE")
      ->expected(1)
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("--generator", *o.generator,
                  "The snag-cloth sample generator (default: beside snag, in the build tree, or "
                  "on PATH)")
      ->type_name("PATH");
  cmd->add_option("-j,--threads", *o.threads, "CPU worker threads; 0 uses every core")
      ->type_name("N")
      ->check(kThreadCount)
      ->capture_default_str();
}

}  // namespace snag::cli
