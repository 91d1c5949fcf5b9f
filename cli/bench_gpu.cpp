// `snag bench gpu`: the CUDA backend's stages timed with CUDA events, next to the CPU backend on
// the same frames and the seed paper's table, with a check that both backends give the same
// filtered frame (pairs, kinds, uncertain tests, counts) on every frame. A benchmark, not a
// test: it prints a table and fails only when the backends differ.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "backend_factory.h"
#include "bench_support.h"
#include "commands.h"
#include "snag/detect/cpu_backend.h"
#include "snag/detect/topology.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/seq/sequence.h"
#include "snag/threads.h"

#ifdef SNAG_HAVE_CUDA
#include "snag/cuda/cuda_backend.h"
#endif

namespace snag::cli {

CLI::App* add_bench_gpu_command(CLI::App& bench, BenchGpuOptions& o) {
  CLI::App* gpu = bench.add_subcommand("gpu",
                                       "Time the CUDA backend's stages with CUDA events, next to "
                                       "the CPU backend and the paper's table");
  add_case_options(gpu, {&o.sizes, &o.data_dir, &o.inputs, &o.generator, &o.threads},
                   "its cloth-ball and n-body frames are cases", "time");
  gpu->add_option("--large", o.large,
                  "Triangles of the large generated cloth, taken from its first frames (0: none)")
      ->type_name("T")
      ->check(kCount)
      ->capture_default_str();
  gpu->add_option("--frames", o.frames, "Timed frames per case on the GPU, after the warm-up")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  gpu->add_option("--warmup", o.warmup, "Untimed frames per case before the timed ones")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  gpu->add_option("--cpu-frames", o.cpu_frames, "Timed frames per case on the CPU")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  gpu->add_option("--device", o.device, "CUDA device, numbered from 0")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  return gpu;
}

#ifndef SNAG_HAVE_CUDA

int run_bench_gpu(const BenchGpuOptions&) {
  throw DeviceUnavailable(std::string("bench gpu: this snag was built without the CUDA backend (") +
                          SNAG_WITHOUT_CUDA_BECAUSE + ")");
}

#else

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// Milliseconds, medians over the timed frames.
struct Row {
  std::string name;
  int triangles = 0;
  int files = 0;
  int timed = 0;
  double build = 0, refit = 0, quality = 0, scan = 0, traverse = 0, classify = 0, frame = 0,
         frame_host = 0, upload = 0;
  double cpu_build = 0, cpu_frame = 0;
  int64_t pairs = 0, candidates = 0;
  bool same = true;
  std::string note;
  /// A SNAG_CUDA_TRACE build's timeline of a device-resident frame: per launch, medians over
  /// the timed frames whose launches came in the most common order.
  std::vector<cuda::CudaBackend::TracedLaunch> trace;
  int traced_frames = 0;
};

/// Per launch, the medians of `frames` (each a frame's launches in start order) over the
/// frames whose launches came in the most common order (the side stream's kernels may start
/// before or after a main-stream one), told by their thread counts; how many those were.
std::pair<std::vector<cuda::CudaBackend::TracedLaunch>, int> median_trace(
    const std::vector<std::vector<cuda::CudaBackend::TracedLaunch> >& frames) {
  // Each frame's order once: its launches' thread counts.
  std::vector<std::vector<int64_t> > order_of(frames.size());
  std::map<std::vector<int64_t>, int> orders;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (const auto& launch : frames[f]) order_of[f].push_back(launch.threads);
    ++orders[order_of[f]];
  }
  if (orders.empty()) return {{}, 0};
  const auto usual = std::ranges::max_element(orders, {}, [](const auto& o) { return o.second; });
  const std::vector<int64_t>& order = usual->first;
  std::vector<cuda::CudaBackend::TracedLaunch> medians(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    std::vector<double> began, first, last;
    for (size_t f = 0; f < frames.size(); ++f) {
      if (order_of[f] != order) continue;
      began.push_back(frames[f][k].began);
      first.push_back(frames[f][k].passed_first);
      last.push_back(frames[f][k].passed_last);
    }
    medians[k] = {order[k], median(began), median(first), median(last)};
  }
  return {medians, usual->second};
}

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The differences between two filtered frames, empty when they are the same.
std::string difference(const detect::FilteredFrame& cpu, const detect::FilteredFrame& gpu) {
  if (cpu.pairs != gpu.pairs)
    return "pairs differ (" + std::to_string(cpu.pairs.size()) + " cpu, " +
           std::to_string(gpu.pairs.size()) + " gpu)";
  if (cpu.kind_certain != gpu.kind_certain) return "certain kinds differ";
  if (cpu.uncertain != gpu.uncertain)
    return "uncertain tests differ (" + std::to_string(cpu.uncertain.size()) + " cpu, " +
           std::to_string(gpu.uncertain.size()) + " gpu)";
  if (cpu.candidate_pairs != gpu.candidate_pairs) return "candidate counts differ";
  if (cpu.filtered_tests != gpu.filtered_tests) return "filtered test counts differ";
  return {};
}

/// Degenerate ids as the checker passes them (the uncertain ones are rare and left out here,
/// the same way for both backends).
std::vector<int32_t> degenerate_of(detect::Backend& backend) {
  return backend.scan_degenerate().degenerate;
}

Row run_case(const BenchCase& c, const BenchGpuOptions& o) {
  const std::vector<mesh::Mesh> meshes = read_case(c, "snag bench gpu").meshes;
  const mesh::Mesh& first = meshes.front();
  const auto vertices = static_cast<int32_t>(first.positions.size());
  const detect::Topology topology = detect::make_topology(first.triangles, vertices);

  Row row;
  row.name = c.name;
  row.triangles = static_cast<int>(first.triangles.size());
  row.files = static_cast<int>(meshes.size());

  auto gpu_owner = make_backend("cuda", o.threads, o.device);
  auto* gpu = dynamic_cast<cuda::CudaBackend*>(gpu_owner.get());
  if (!gpu) throw InternalError("bench gpu: the cuda backend is not a cuda::CudaBackend");
  auto cpu = detect::make_cpu_backend(o.threads);
  gpu->set_topology(topology);
  cpu->set_topology(topology);
  std::vector<std::span<const geom::Vec3d> > frames;
  for (const mesh::Mesh& m : meshes) frames.emplace_back(m.positions);
  gpu->upload_resident_frames(frames);

  // Same answers on every frame, from a fresh build of each.
  for (size_t f = 0; f < meshes.size(); ++f) {
    cpu->set_positions(meshes[f].positions);
    gpu->set_positions(meshes[f].positions);
    const std::vector<int32_t> degenerate = degenerate_of(*cpu);
    if (degenerate != degenerate_of(*gpu)) {
      row.same = false;
      row.note = "frame " + std::to_string(f) + ": degenerate triangles differ";
    }
    cpu->build();
    gpu->build();
    if (cpu->tree_quality() != gpu->tree_quality()) {
      row.same = false;
      row.note = "frame " + std::to_string(f) + ": tree quality differs";
    }
    const detect::FilteredFrame a = cpu->detect(degenerate), b = gpu->detect(degenerate);
    if (const std::string d = difference(a, b); !d.empty()) {
      row.same = false;
      row.note = "frame " + std::to_string(f) + ": " + d;
    }
    row.pairs = static_cast<int64_t>(b.pairs.size());
    row.candidates = b.candidate_pairs;
  }

  const int iterations = std::max(0, o.warmup) + std::max(1, o.frames);
  const auto file_count = static_cast<int>(meshes.size());
  std::vector<double> build, refit, quality, scan, traverse, classify, frame, frame_host, upload;
  // Builds, device-resident positions.
  for (int it = 0; it < iterations; ++it) {
    gpu->select_resident_frame(it % file_count);
    gpu->build();
    if (it >= o.warmup) build.push_back(gpu->last_times().build);
  }
  // Stages on their own (device-resident positions): refit, quality, traversal with the
  // narrow phase, and the rest of detect; refit() here does the refit, no scan ran ahead of it.
  for (int it = 0; it < iterations; ++it) {
    gpu->select_resident_frame(it % file_count);
    gpu->refit();
    gpu->tree_quality();
    gpu->detect({});
    if (it < o.warmup) continue;
    const cuda::StageTimes t = gpu->last_times();
    refit.push_back(t.refit);
    quality.push_back(t.quality);
    traverse.push_back(t.traverse);
    classify.push_back(t.classify);
  }
  // Whole frames as the checker runs them: scan (with the refit and the quality queued ahead),
  // refit, quality, traversal with the narrow phase, pairs back on the host; positions already
  // on the device, then from host memory.
  // In a SNAG_CUDA_TRACE build, each device-resident frame's launches (taken after its time).
  std::vector<std::vector<cuda::CudaBackend::TracedLaunch> > traces;
  for (int from_host = 0; from_host < 2; ++from_host) {
    for (int it = 0; it < iterations; ++it) {
      const int f = it % file_count;
      if (!from_host) gpu->select_resident_frame(f);
      if (!from_host) gpu->take_stream_trace();  // what came before is not this frame's
      gpu->start_timer();
      if (from_host) gpu->set_positions(meshes[f].positions);
      const std::vector<int32_t> degenerate = degenerate_of(*gpu);
      gpu->refit();
      gpu->tree_quality();
      gpu->detect(degenerate);
      const double ms = gpu->stop_timer();
      if (!from_host && it >= o.warmup) traces.push_back(gpu->take_stream_trace());
      if (it < o.warmup) continue;
      const cuda::StageTimes t = gpu->last_times();
      if (from_host) {
        frame_host.push_back(ms);
        upload.push_back(t.upload);
      } else {
        frame.push_back(ms);
        scan.push_back(t.scan);
      }
    }
  }
  // The CPU backend on the same frames (host clock; its stages end when their loops do).
  std::vector<double> cpu_build, cpu_frame;
  for (int it = 0; it < 1 + std::max(1, o.cpu_frames); ++it) {
    const int f = it % file_count;
    cpu->set_positions(meshes[f].positions);
    auto start = Clock::now();
    cpu->build();
    const double build_ms = ms_since(start);
    start = Clock::now();
    const std::vector<int32_t> degenerate = degenerate_of(*cpu);
    cpu->refit();
    cpu->tree_quality();
    cpu->detect(degenerate);
    const double frame_ms = ms_since(start);
    if (it == 0) continue;
    cpu_build.push_back(build_ms);
    cpu_frame.push_back(frame_ms);
  }
  row.timed = static_cast<int>(frame.size());
  row.build = median(build);
  row.refit = median(refit);
  row.quality = median(quality);
  row.scan = median(scan);
  row.traverse = median(traverse);
  row.classify = median(classify);
  row.frame = median(frame);
  row.frame_host = median(frame_host);
  row.upload = median(upload);
  row.cpu_build = median(cpu_build);
  row.cpu_frame = median(cpu_frame);
  std::tie(row.trace, row.traced_frames) = median_trace(traces);
  return row;
}

void print_tables(const std::vector<Row>& rows, const std::string& device, int threads) {
  std::printf(
      "snag bench gpu: %s; CPU backend with %d threads; milliseconds, medians over the timed "
      "frames\n",
      device.c_str(), threads);
  std::printf(
      "refit, quality, traverse, classify: each stage on its own; scan: the checker's scan with "
      "the refit, the quality and the last frame's detect queued ahead of their calls (its wait "
      "ends once the host has queued them all);\nframe: scan, refit, quality, detect as the "
      "checker calls them, pairs back on the host (dev: positions on the device; host: uploaded "
      "from host memory first)\n\n");
  std::printf("%-14s %8s %6s %8s %7s %7s %7s %8s %8s %8s %8s %9s %9s %8s %8s %5s\n", "case", "tris",
              "timed", "build", "refit", "quality", "scan", "traverse", "classify", "frame",
              "frame", "CPU build", "CPU frame", "CPU/GPU", "pairs", "same");
  std::printf("%-14s %8s %6s %8s %7s %7s %7s %8s %8s %8s %8s %9s %9s %8s %8s %5s\n", "", "", "", "",
              "", "", "", "", "", "dev", "host", "", "", "frame", "", "");
  for (const Row& r : rows) {
    std::printf(
        "%-14s %8d %6d %8.3f %7.3f %7.3f %7.3f %8.3f %8.3f %8.3f %8.3f %9.2f %9.2f %7.0fx %8lld "
        "%5s\n",
        r.name.c_str(), r.triangles, r.timed, r.build, r.refit, r.quality, r.scan, r.traverse,
        r.classify, r.frame, r.frame_host, r.cpu_build, r.cpu_frame,
        r.frame > 0 ? r.cpu_frame / r.frame : 0.0, static_cast<long long>(r.pairs),
        r.same ? "yes" : "NO");
    if (!r.note.empty()) std::printf("  %s\n", r.note.c_str());
  }
  if (std::ranges::any_of(rows, [](const Row& r) { return !r.trace.empty(); })) {
    std::printf(
        "\nStream trace (a SNAG_CUDA_TRACE build): each device-resident frame's kernel launches in "
        "start order, microseconds on the device's clock from the first one's start, medians over "
        "the timed frames whose launches came in the usual order; began = its first block's "
        "start, passed = its first and last blocks past the wait for the kernel ahead on its "
        "stream (the first pass is about where that kernel ended); threads tell the kernels apart "
        "(cuda/NOTES.md)\n");
    for (const Row& r : rows) {
      if (r.trace.empty()) continue;
      std::printf("%s (%d frames):\n", r.name.c_str(), r.traced_frames);
      std::printf("  %6s %10s %10s %12s %11s\n", "launch", "threads", "began", "passed first",
                  "passed last");
      for (size_t k = 0; k < r.trace.size(); ++k)
        std::printf("  %6zu %10lld %10.2f %12.2f %11.2f\n", k,
                    static_cast<long long>(r.trace[k].threads), r.trace[k].began,
                    r.trace[k].passed_first, r.trace[k].passed_last);
    }
  }
  std::printf("\nThe seed paper's table (GPU / CPU), for the same sizes:\n");
  std::printf("%9s %24s %22s %22s\n", "triangles", "build", "refit", "traverse");
  std::printf("%9s %24s %22s %22s\n", "2,244", "23.94 ms / 5.71 ms", "0.16 us / 0.31 us",
              "1.19 ms / 10.28 ms");
  std::printf("%9s %24s %22s %22s\n", "27,030", "59.12 ms / 45.18 ms", "0.18 us / 1.28 us",
              "12.52 ms / 162.92 ms");
  std::printf("%9s %24s %22s %22s\n", "35,992", "0.21 s / 0.98 s", "0.35 us / 4.81 us",
              "0.41 s / 8.65 s");
}

}  // namespace

int run_bench_gpu(const BenchGpuOptions& o) {
  if (cuda_devices() == 0) {
    const std::string problem = cuda_runtime_problem();
    throw DeviceUnavailable("bench gpu: no CUDA device is usable here (" +
                            (problem.empty() ? "no NVIDIA GPU, or no driver for it" : problem) +
                            ")");
  }
  ScratchDir scratch;
  std::vector<BenchCase> cases;
  const fs::path data = data_folder(o.data_dir);
  add_data_case(cases, data, o.data_dir, "cloth-ball", "scalable-ccd/cloth-ball", "snag bench gpu");
  add_data_case(cases, data, o.data_dir, "n-body", "scalable-ccd/n-body-simulation",
                "snag bench gpu");
  for (const std::string& input : o.inputs)
    cases.push_back(sequence_case(fs::path(input).filename().string(), input));
  // Generated cases: the paper's sizes folded on the sphere (settled, 4 frames cycled), then the
  // large cloth from its first 2 frames (settling a million triangles takes minutes).
  std::vector<BenchCase> generated;
  for (int size : o.sizes) {
    if (size <= 0) continue;
    const fs::path dir = scratch.path() / std::to_string(size);
    generated.push_back({"cloth " + std::to_string(size),
                         generated_cloth(o.generator, size, settle_frames, 4, dir)});
  }
  if (o.large > 0) {
    const fs::path dir = scratch.path() / "large";
    cases.push_back(
        {"cloth " + std::to_string(o.large), generated_cloth(o.generator, o.large, 0, 2, dir)});
  }
  cases.insert(cases.begin(), generated.begin(), generated.end());
  if (cases.empty())
    throw UsageError("nothing to time: no --sizes, no --large, no data folder, no --input");

  std::vector<Row> rows;
  for (const BenchCase& c : cases) rows.push_back(run_case(c, o));
  auto probe = make_backend("cuda", o.threads, o.device);
  print_tables(rows, dynamic_cast<cuda::CudaBackend&>(*probe).device_name(),
               thread_count(o.threads));
  if (!std::all_of(rows.begin(), rows.end(), [](const Row& r) { return r.same; }))
    throw InternalError("the CPU and CUDA backends gave different results (see the table)");
  return 0;
}

#endif

}  // namespace snag::cli
