// `snag bench cpu`: snag's CPU path and CGAL's self_intersections timed side by side on the
// same frames (generated cloth at the paper's sizes, the shared cloth-ball frames, and any
// --input sequence), with a check that both found the same pairs. A benchmark, not a test:
// it prints a table and fails only when the pairs differ.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "backend_factory.h"
#include "bench_support.h"
#include "commands.h"
#include "snag/detect/checker.h"
#include "snag/detect/cpu_backend.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/seq/sequence.h"
#include "snag/threads.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/cgal_resolver.h"

namespace snag::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Row {
  std::string name;
  int triangles = 0;
  int frames = 0;
  int timed = 0;
  double build = 0, refit = 0, traverse = 0, exact = 0, total = 0, cgal = 0;
  double read = 0;        ///< seconds to read one frame (median), one thread
  double read_bytes = 0;  ///< bytes per frame file (median)
  int64_t pairs = 0;
  bool same = true;
  std::string note;
};

detect::CpuWalkWidth walk_width(int lanes) {
  return lanes == 4   ? detect::CpuWalkWidth::four
         : lanes == 8 ? detect::CpuWalkWidth::eight
                      : detect::CpuWalkWidth::automatic;
}

Row run_case(const BenchCase& c, const BenchOptions& o) {
  const CaseFrames read = read_case(c, "snag bench");
  const std::vector<mesh::Mesh>& meshes = read.meshes;
  const mesh::Mesh& first = meshes.front();
  const int32_t vertices = static_cast<int32_t>(first.positions.size());

  Row row;
  row.name = c.name;
  row.triangles = static_cast<int>(first.triangles.size());
  row.frames = static_cast<int>(meshes.size());

  // Two checkers over the same frames: one refits (the steady state of a sequence), one
  // rebuilds every frame (the build time per frame).
  auto resolver = validators::make_cgal_resolver();
  const detect::CpuWalkWidth width = walk_width(o.walk_lanes);
  detect::Checker refitting(detect::make_cpu_backend(o.threads, width), resolver,
                            {detect::RebuildPolicy::never});
  detect::Checker rebuilding(detect::make_cpu_backend(o.threads, width), resolver,
                             {detect::RebuildPolicy::always});
  refitting.set_triangles(first.triangles, vertices);
  rebuilding.set_triangles(first.triangles, vertices);
  // CGAL's halfedge mesh is built once, as snag's topology is: only positions change per frame.
  validators::CgalSequence cgal_sequence(first.positions, first.triangles);

  // Frames are visited cyclically, so a two-frame case still gives --frames timed samples.
  const int iterations = std::max(0, o.warmup) + std::max(1, o.frames);
  std::vector<double> build, refit, traverse, exact, total, cgal;
  for (int it = 0; it < iterations; ++it) {
    const mesh::Mesh& m = meshes[it % meshes.size()];
    const detect::FrameResult built = rebuilding.check(m.positions);
    const detect::FrameResult r = refitting.check(m.positions);
    const auto cgal_started = Clock::now();
    cgal_sequence.set_positions(m.positions);
    const auto reference = cgal_sequence.self_intersections();
    const double cgal_seconds = std::chrono::duration<double>(Clock::now() - cgal_started).count();
    if (validators::pair_ids(r.pairs) != reference ||
        validators::pair_ids(built.pairs) != reference) {
      row.same = false;
      row.note = "frame " + std::to_string(it % meshes.size()) + ": snag " +
                 std::to_string(r.pairs.size()) + " pairs, CGAL " +
                 std::to_string(reference.size());
    }
    if (it < o.warmup) continue;
    build.push_back(built.times.build);
    refit.push_back(r.times.refit);
    traverse.push_back(r.times.traverse);
    exact.push_back(r.times.exact + r.times.classify);
    total.push_back(r.times.total());
    cgal.push_back(cgal_seconds);
    row.pairs = static_cast<int64_t>(r.pairs.size());
  }
  row.timed = static_cast<int>(total.size());
  row.build = median(build);
  row.refit = median(refit);
  row.traverse = median(traverse);
  row.exact = median(exact);
  row.total = median(total);
  row.cgal = median(cgal);
  row.read = median(read.read_seconds);
  row.read_bytes = median(read.read_bytes);
  return row;
}

void print_table(const std::vector<Row>& rows, int threads, int lanes) {
  std::printf(
      "snag bench cpu: %d threads, walks of %d leaves; medians over the timed frames, "
      "milliseconds per frame\n",
      threads, lanes);
  std::printf(
      "snag total = refit + traverse + exact/classify (the tree is built once per topology; build "
      "is\n"
      "the time of one rebuild); CGAL = self_intersections on its halfedge mesh built once, "
      "positions\n"
      "updated per frame, sequential; read = snag reading one frame file from the page cache, one "
      "thread\n\n");
  std::printf("%-22s %9s %6s %8s %8s %8s %8s %8s %8s %9s %9s %8s %8s %5s\n", "case", "triangles",
              "frames", "read", "MB/s", "build", "refit", "traverse", "exact", "total", "CGAL",
              "CGAL/snag", "pairs", "same");
  for (const Row& r : rows) {
    const double ratio = r.total > 0 ? r.cgal / r.total : 0;
    const double rate = r.read > 0 ? r.read_bytes / r.read / 1e6 : 0;
    std::printf("%-22s %9d %6d %8.3f %8.0f %8.3f %8.3f %8.3f %8.3f %8.3f %9.3f %8.1fx %8lld %5s\n",
                r.name.c_str(), r.triangles, r.timed, r.read * 1e3, rate, r.build * 1e3,
                r.refit * 1e3, r.traverse * 1e3, r.exact * 1e3, r.total * 1e3, r.cgal * 1e3, ratio,
                static_cast<long long>(r.pairs), r.same ? "yes" : "NO");
    if (!r.note.empty()) std::printf("  %s\n", r.note.c_str());
  }
}

}  // namespace

CLI::App* add_bench_command(CLI::App& app, BenchOptions& o) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks (not tests)");
  bench->require_subcommand(1, 1);
  CLI::App* cpu = bench->add_subcommand(
      "cpu", "Time snag's CPU path and CGAL's self_intersections side by side on the same frames");
  add_case_options(cpu, {&o.sizes, &o.data_dir, &o.inputs, &o.generator, &o.threads},
                   "its scalable-ccd/cloth-ball frames are a case", "time");
  cpu->add_option("--frames", o.frames, "Timed frames per case, after the warm-up")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  cpu->add_option("--warmup", o.warmup, "Untimed frames per case before the timed ones")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  cpu->add_option("--walk-lanes", o.walk_lanes,
                  "Leaves that walk the tree together: 4, 8 (needs AVX2 to be fast), or 0 for "
                  "8 where the CPU has AVX2, else 4")
      ->type_name("N")
      ->check(CLI::IsMember({0, 4, 8}))
      ->capture_default_str();
  return cpu;
}

int run_bench_cpu(const BenchOptions& o) {
  ScratchDir scratch;
  std::vector<BenchCase> cases;
  add_data_case(cases, data_folder(o.data_dir), o.data_dir, "cloth-ball", "scalable-ccd/cloth-ball",
                "snag bench");
  for (const std::string& input : o.inputs)
    cases.push_back(sequence_case(fs::path(input).filename().string(), input));
  // Generated cases last to be made (after the arguments were checked), first in the table.
  std::vector<BenchCase> generated;
  for (int size : o.sizes) {
    if (size <= 0) continue;
    const fs::path dir = scratch.path() / std::to_string(size);
    generated.push_back({"cloth " + std::to_string(size),
                         generated_cloth(o.generator, size, settle_frames, o.frames, dir)});
  }
  cases.insert(cases.begin(), generated.begin(), generated.end());
  if (cases.empty()) throw UsageError("nothing to time: no --sizes, no data folder, no --input");

  std::vector<Row> rows;
  for (const BenchCase& c : cases) rows.push_back(run_case(c, o));
  print_table(rows, thread_count(o.threads), detect::cpu_walk_lanes(walk_width(o.walk_lanes)));
  const bool all_same = std::all_of(rows.begin(), rows.end(), [](const Row& r) { return r.same; });
  if (!all_same) throw InternalError("snag and CGAL found different pairs (see the table)");
  return 0;
}

}  // namespace snag::cli
