// snag: finds self-intersections in cloth animation sequences.
//
// This file holds the one place where exceptions become exit statuses:
//   0 clean, 1 intersections found (per --fail-on; returned by the command, not thrown),
//   2 usage error, 3 input or output error, 4 internal error or no usable CUDA device when one
//   was asked for.
#include <malloc.h>
#include <signal.h>
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "backend_factory.h"
#include "commands.h"
#include "snag/error.h"
#include "snag/report/write.h"

namespace {

/// SIGINT, SIGTERM, SIGHUP (Ctrl-C, a render farm's kill, a closed terminal): the report
/// temporaries go, then the signal does what it would have done, so the status says so.
extern "C" void on_terminating_signal(int signal_number) {
  snag::report::remove_temporaries_on_signal();
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void remove_temporaries_when_killed() {
  struct sigaction action {};
  action.sa_handler = on_terminating_signal;
  sigemptyset(&action.sa_mask);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction was {};
    // A signal the caller ignores (nohup, a background job's SIGINT) stays ignored.
    if (::sigaction(signal_number, nullptr, &was) == 0 && was.sa_handler == SIG_IGN) continue;
    ::sigaction(signal_number, &action, nullptr);
  }
}

/// An option given twice takes its last value, as wrapper scripts that append their overrides
/// expect (`snag check $STUDIO_DEFAULTS --threads 4`); CLI11 would refuse the run ("At Most 1
/// required but received 2"). Repeatable options keep every value.
void take_the_last_of_repeated_options(CLI::App& app) {
  for (CLI::Option* option : app.get_options())
    if (option->nonpositional() && option->get_items_expected_max() == 1 &&
        option->get_multi_option_policy() == CLI::MultiOptionPolicy::Throw)
      option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    take_the_last_of_repeated_options(*command);
}

/// The names of `app`'s commands, for a message: "check or bench", "cpu, gpu, accuracy, io or
/// scene".
std::string command_names(const CLI::App& app) {
  const std::vector<const CLI::App*> commands = app.get_subcommands({});
  std::string names;
  for (size_t i = 0; i < commands.size(); ++i) {
    names += i == 0 ? "" : i + 1 == commands.size() ? " or " : ", ";
    names += commands[i]->get_name();
  }
  return names;
}

/// `status`, once what is buffered for standard output has been written; 3 when it could not
/// be (a full disk, a closed file): a summary or help that never reached its reader is no
/// success, and a gate reading it would see nothing, or half of it.
int status_once_output_is_written(int status) {
  errno = 0;  // what a failing flush leaves is its own error; an earlier one's is not told
  std::cout.flush();
  if (std::cout) return status;
  const int err = errno;
  std::cerr << "snag: cannot write to standard output"
            << (err != 0 ? std::string(": ") + std::strerror(err) : std::string()) << "\n";
  return 3;
}

/// CLI11's message for a command line whose command or benchmark is missing or misspelt ("A
/// subcommand is required", also for `snag --bogus`): what was expected, and what was found.
/// `app` is the top-level app, whatever level failed: the one that failed is the deepest
/// command parsed.
std::string failure_text(const CLI::App* app, const CLI::Error& error) {
  if (dynamic_cast<const CLI::RequiredError*>(&error) == nullptr ||
      std::string_view(error.what()) != "A subcommand is required")
    return CLI::FailureMessage::simple(app, error);
  const CLI::App* failed = app;
  while (!failed->get_subcommands().empty()) failed = failed->get_subcommands().front();
  const std::string expected = command_names(*failed);
  const std::vector<std::string> left = failed->remaining();
  std::string found = "nothing";
  if (!left.empty())
    found = left.front().starts_with("-") ? "the option " + left.front() : "'" + left.front() + "'";
  const std::string prefix = failed == app ? "" : failed->get_name() + ": ";
  return prefix + "expected a command, " + expected + ", found " + found +
         "\nRun with --help for more information.\n";
}

}  // namespace

int main(int argc, char** argv) {
  remove_temporaries_when_killed();
  // Every frame allocates and frees the same few large arrays (positions, faces, report text)
  // on reader threads and the checker's. glibc serves blocks above its mmap threshold with a
  // fresh mmap and returns them with munmap, whose TLB shootdown interrupts every core running
  // the checker's threads: keep such blocks in the heap for reuse instead. Memory stays that of
  // the largest frames in flight.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  CLI::App app{
      "snag finds where a cloth animation goes through itself: every intersecting "
      "triangle pair of every frame, labelled crossing or touching.",
      "snag"};
  // What to do when a GPU runs out of memory: the commands with --backend can check on the CPU.
  std::string out_of_memory_advice = "; run it on a GPU with more free memory";
  try {
    app.set_version_flag("--version",
                         std::string("snag ") + SNAG_VERSION + "\n" + snag::cli::cuda_build_line());
    // CLI11's own messages (a bad value, an unknown option) start as snag's do; set before the
    // subcommands are added, which copy it.
    app.failure_message([](const CLI::App* failed, const CLI::Error& e) {
      return "snag: error: " + failure_text(failed, e);
    });
    app.require_subcommand(1, 1);
    snag::cli::CheckOptions check;
    CLI::App* check_command = snag::cli::add_check_command(app, check);
    snag::cli::BenchOptions bench;
    CLI::App* bench_cpu_command = snag::cli::add_bench_command(app, bench);
    snag::cli::BenchGpuOptions bench_gpu;
    CLI::App* bench_gpu_command =
        snag::cli::add_bench_gpu_command(*app.get_subcommand("bench"), bench_gpu);
    snag::cli::BenchAccuracyOptions bench_accuracy;
    CLI::App* bench_accuracy_command =
        snag::cli::add_bench_accuracy_command(*app.get_subcommand("bench"), bench_accuracy);
    snag::cli::BenchIoOptions bench_io;
    CLI::App* bench_io_command =
        snag::cli::add_bench_io_command(*app.get_subcommand("bench"), bench_io);
    snag::cli::BenchSceneOptions bench_scene;
    CLI::App* bench_scene_command =
        snag::cli::add_bench_scene_command(*app.get_subcommand("bench"), bench_scene);
    // Set after the subcommands are added, so that they do not inherit it.
    app.footer(
        "Exit status: 0 clean, 1 intersections found (see check --fail-on), 2 usage error, "
        "3 input or output error, 4 internal or GPU error. See snag(1).");

    take_the_last_of_repeated_options(app);

    // A first word that names no command: CLI11 would answer "A subcommand is required" (and
    // `snag report --help` would print the top-level help and exit 0).
    const auto names_a_command = [&](const std::string& word) {
      for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
        if (command->check_name(word)) return true;
      return false;
    };
    if (argc > 1 && argv[1][0] != '-' && !names_a_command(argv[1]))
      throw snag::UsageError("unknown command '" + std::string(argv[1]) + "'; expected " +
                             command_names(app));
    app.parse(argc, argv);
    if (check_command->parsed() || bench_scene_command->parsed())
      out_of_memory_advice = "; check it on the CPU with --backend cpu";
    int status = -1;
    if (check_command->parsed()) status = snag::cli::run_check(check);
    if (bench_cpu_command->parsed()) status = snag::cli::run_bench_cpu(bench);
    if (bench_gpu_command->parsed()) status = snag::cli::run_bench_gpu(bench_gpu);
    if (bench_accuracy_command->parsed()) status = snag::cli::run_bench_accuracy(bench_accuracy);
    if (bench_io_command->parsed()) status = snag::cli::run_bench_io(bench_io);
    if (bench_scene_command->parsed()) status = snag::cli::run_bench_scene(bench_scene);
    if (status < 0) throw snag::InternalError("no subcommand ran");
    return status_once_output_is_written(status);
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive here too, with CLI11's success code.
    const int code = app.exit(e);
    return code == 0 ? status_once_output_is_written(0) : 2;
  } catch (const snag::UsageError& e) {
    std::cerr << "snag: error: " << e.what() << "\nRun with --help for more information.\n";
    return 2;
  } catch (const snag::InputError& e) {
    std::cerr << "snag: input error: " << e.what() << "\n";
    return 3;
  } catch (const snag::report::WriteError& e) {
    std::cerr << "snag: cannot write the report: " << e.what() << "\n";
    return 3;
  } catch (const snag::cli::DeviceUnavailable& e) {
    std::cerr << "snag: error: " << e.what() << "\n";
    return 4;
  } catch (const snag::OutOfMemory& e) {
    std::cerr << "snag: error: " << e.what() << out_of_memory_advice << "\n";
    return 4;
  } catch (const snag::InternalError& e) {
    std::cerr << "snag: internal error: " << e.what() << "\n";
    return 4;
  } catch (const std::exception& e) {
    std::cerr << "snag: internal error: " << e.what() << "\n";
    return 4;
  } catch (...) {
    std::cerr << "snag: internal error: unknown exception\n";
    return 4;
  }
}
