// snag: finds self-intersections in cloth animation sequences.
//
// This file holds the one place where exceptions become exit statuses:
//   0 clean, 1 intersections found (per --fail-on; returned by the command, not thrown),
//   2 usage error, 3 input or output error, 4 internal error or no usable CUDA device when one
//   was asked for.
#include <malloc.h>
#include <signal.h>
#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>

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
  try {
    app.set_version_flag("--version", SNAG_VERSION);
    // CLI11's own messages (a bad value, an unknown option) start as snag's do; set before the
    // subcommands are added, which copy it.
    app.failure_message([](const CLI::App* failed, const CLI::Error& e) {
      return "snag: error: " + CLI::FailureMessage::simple(failed, e);
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
        "3 input or output error, 4 internal error. See snag(1).");

    // A first word that names no command: CLI11 would answer "A subcommand is required" (and
    // `snag report --help` would print the top-level help and exit 0).
    const auto names_a_command = [&](const std::string& word) {
      for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
        if (command->check_name(word)) return true;
      return false;
    };
    if (argc > 1 && argv[1][0] != '-' && !names_a_command(argv[1]))
      throw snag::UsageError("unknown command '" + std::string(argv[1]) +
                             "'; expected check or bench");
    app.parse(argc, argv);
    if (check_command->parsed()) return snag::cli::run_check(check);
    if (bench_cpu_command->parsed()) return snag::cli::run_bench_cpu(bench);
    if (bench_gpu_command->parsed()) return snag::cli::run_bench_gpu(bench_gpu);
    if (bench_accuracy_command->parsed()) return snag::cli::run_bench_accuracy(bench_accuracy);
    if (bench_io_command->parsed()) return snag::cli::run_bench_io(bench_io);
    if (bench_scene_command->parsed()) return snag::cli::run_bench_scene(bench_scene);
    throw snag::InternalError("no subcommand ran");
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive here too, with CLI11's success code.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
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
