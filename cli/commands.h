// The subcommands of `snag`: each file registers its options on the CLI11 app and runs the
// command, returning its exit status (0, or 1 when intersections fail the run). Errors are
// thrown, and cli/main.cpp turns them into exit statuses.
#pragma once

#include <CLI/CLI.hpp>

#include <charconv>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace snag::cli {

/// The most threads --threads takes: far past any machine's cores, short of the thread counts
/// that exhaust a process's stacks (-j 100000 crashed the run).
inline constexpr int kMostThreads = 4096;

/// A number above `least` (`strictly`) or at least it, NaN refused: CLI11's PositiveNumber and
/// NonNegativeNumber, whose messages print the largest double in full ("not in range 0.000000
/// to 179769313486...").
inline CLI::Validator number_above(double least, bool strictly, const std::string& description) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return "expected a number, got '" + text + "'";
        if (strictly ? value > least : value >= least) return {};
        return "expected a number " + std::string(strictly ? "> " : ">= ") +
               CLI::detail::to_string(least) + ", got '" + text + "'";
      },
      description);
}
inline const CLI::Validator kNonNegative = number_above(0, false, "NONNEGATIVE");

/// A whole number from `least` to `most`: CLI11's Range answers a word with "Value abc not in
/// range 0 to 4096", and an int option given 1.5 fails with "Could not convert".
inline CLI::Validator whole_number(int64_t least, int64_t most, const std::string& description) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        int64_t value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (error == std::errc() && stop == end && value >= least && value <= most) return {};
        std::string range = most == std::numeric_limits<int>::max()
                                ? ">= " + std::to_string(least)
                                : "from " + std::to_string(least) + " to " + std::to_string(most);
        return "expected a whole number " + range + ", got '" + text + "'";
      },
      description);
}
/// --threads N: 0 (every core) to kMostThreads.
inline const CLI::Validator kThreadCount = whole_number(0, kMostThreads, "INT in [0 - 4096]");
inline const CLI::Validator kPositiveCount =
    whole_number(1, std::numeric_limits<int>::max(), "POSITIVE");
inline const CLI::Validator kCount =
    whole_number(0, std::numeric_limits<int>::max(), "NONNEGATIVE");

/// An option's value that is not an option: `--out -q` took -q as the directory and wrote the
/// reports into ./-q, `--obstacle -q` read the file -q. `what` is what was expected.
inline CLI::Validator not_an_option(const std::string& what) {
  return CLI::Validator(
      [what](std::string& value) -> std::string {
        if (value.size() > 1 && value[0] == '-')
          return "expected " + what + ", found the option " + value + " (write ./" + value +
                 " for one of that name)";
        return "";
      },
      "", "not an option");
}

/// Options of `snag check`, filled by CLI11.
struct CheckOptions {
  std::string sequence;
  std::vector<std::string> obstacles;        ///< --obstacle, in order
  std::string scene;                         ///< --scene FILE
  bool split_groups = false;                 ///< --split-groups
  std::vector<std::string> obstacle_groups;  ///< --obstacle-group, with --split-groups
  std::string out_dir;
  std::string frames;
  std::optional<double> weld;
  std::string rebuild = "auto";
  double rebuild_threshold = 1.5;
  std::string backend = "auto";
  int device = 0;
  int threads = 0;
  std::string fail_on = "crossing";
  std::string baseline;  ///< --baseline FILE, empty when not given
  std::string junit;     ///< --junit FILE, empty when not given
  std::string exact = "uncertain";
  bool quiet = false;
};

CLI::App* add_check_command(CLI::App& app, CheckOptions& options);
int run_check(const CheckOptions& options);

/// Options of `snag bench cpu`, filled by CLI11.
struct BenchOptions {
  std::vector<int> sizes = {2244, 27030, 35992};
  int frames = 5;
  int warmup = 1;
  std::string data_dir;
  std::vector<std::string> inputs;
  std::string generator;
  int threads = 0;
  int walk_lanes = 0;  ///< leaves per walk on the CPU: 4, 8, or 0 for the machine's choice
};

/// Adds `bench` and its `cpu` subcommand; returns the `cpu` subcommand.
CLI::App* add_bench_command(CLI::App& app, BenchOptions& options);
int run_bench_cpu(const BenchOptions& options);

/// Options of `snag bench gpu`, filled by CLI11.
struct BenchGpuOptions {
  std::vector<int> sizes = {2244, 27030, 35992};
  int large = 1000000;
  int frames = 50;
  int warmup = 5;
  int cpu_frames = 5;
  std::string data_dir;
  std::vector<std::string> inputs;
  std::string generator;
  int threads = 0;
  int device = 0;
};

/// Adds the `gpu` subcommand to `bench` (the command add_bench_command made); returns it.
CLI::App* add_bench_gpu_command(CLI::App& bench, BenchGpuOptions& options);
int run_bench_gpu(const BenchGpuOptions& options);

/// Options of `snag bench accuracy`, filled by CLI11.
struct BenchAccuracyOptions {
  std::vector<int> sizes = {2244, 27030, 35992};
  int frames = 2;
  int warmup = 1;
  std::string hard_dir;
  std::string data_dir;
  std::vector<std::string> inputs;
  std::string generator;
  int threads = 0;
  int device = 0;
  std::string out_dir;
};

/// Adds the `accuracy` subcommand to `bench`; returns it.
CLI::App* add_bench_accuracy_command(CLI::App& bench, BenchAccuracyOptions& options);
int run_bench_accuracy(const BenchAccuracyOptions& options);

/// Options of `snag bench io`, filled by CLI11.
struct BenchIoOptions {
  int size = 35992;
  int frames = 200;
  int passes = 5;
  std::vector<int> memory_frames = {10, 1000};
  std::string data_dir;
  std::vector<std::string> inputs;
  std::string generator;
  int threads = 0;
  int device = 0;
};

/// Adds the `io` subcommand to `bench`; returns it.
CLI::App* add_bench_io_command(CLI::App& bench, BenchIoOptions& options);
int run_bench_io(const BenchIoOptions& options);

/// Options of `snag bench scene`, filled by CLI11.
struct BenchSceneOptions {
  int size = 35992;
  int obstacle_size = 50000;
  int frames = 10;
  int warmup = 2;
  std::string backend = "both";
  std::string generator;
  int threads = 0;
  int device = 0;
};

/// Adds the `scene` subcommand to `bench`; returns it.
CLI::App* add_bench_scene_command(CLI::App& bench, BenchSceneOptions& options);
int run_bench_scene(const BenchSceneOptions& options);

}  // namespace snag::cli
