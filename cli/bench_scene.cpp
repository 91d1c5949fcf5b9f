// `snag bench scene`: what a scene costs per frame, side by side in one run, on each backend.
// A generated cloth falls on a sphere; the same sphere, as a UV-sphere obstacle, makes the
// scenes:
//   cloth alone          - the cloth checked against itself;
//   still obstacle       - with the sphere as one file: built (uploaded) once, then only its
//                          cross check each frame, never a refit;
//   moving obstacle      - the sphere as a sequence, translated a little each frame: its
//                          refit and cross check each frame;
//   obstacle self too    - the same, the sphere also checked against itself (a check nobody
//                          asked for in a real scene);
//   frozen frame         - every object's file a copy of one frame: each later frame is
//                          checked by a comparison (its checks reused), against its reading.
// Checking is timed from memory (frames read beforehand), reading one thread apart, and the
// frame loop of `snag check` as a whole. A benchmark, not a test: it prints the tables and fails
// only when something cannot run or the frame loop finds other pairs than checking from memory.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "backend_factory.h"
#include "bench_support.h"
#include "check_sequence.h"
#include "commands.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/scene/scene.h"
#include "snag/scene/scene_frames.h"
#include "snag/seq/sequence.h"
#include "snag/threads.h"

namespace snag::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// ---------------------------------------------------------------------------------------------
// The obstacle: the generator's sphere (samples/cloth_sim.h: centre at the origin, radius 0.5;
// the cloth is kept 0.01 outside it), so that the draped cloth lies over its faces and the
// cross check has candidates to test.

constexpr double kSphereRadius = 0.5;
/// The moving obstacle's translation per frame along x: small beside the cloth's 0.01 gap, so
/// that the scene stays the same while every vertex moves.
constexpr double kStepPerFrame = 1e-4;
/// Fresh checkers whose first frame is timed, per scene and backend.
constexpr int kFirstFrameSamples = 3;

/// A latitude-longitude sphere of about `triangles` triangles centred at the origin: `segments`
/// vertices around each of segments / 2 - 1 rings plus two poles, segments^2 - 2 segments
/// triangles, closed and wound counter-clockwise seen from outside (penetration is measured
/// against it in `snag check`'s loop).
mesh::Mesh uv_sphere(int triangles) {
  int segments = 2 * static_cast<int>(std::lround((1 + std::sqrt(1.0 + triangles)) / 2));
  segments = std::max(segments, 4);
  const int bands = segments / 2;
  mesh::Mesh m;
  m.positions.push_back({0, kSphereRadius, 0});
  for (int i = 1; i < bands; ++i) {
    const double theta = std::numbers::pi * i / bands;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      m.positions.push_back({kSphereRadius * std::sin(theta) * std::cos(phi),
                             kSphereRadius * std::cos(theta),
                             kSphereRadius * std::sin(theta) * std::sin(phi)});
    }
  }
  const auto south = static_cast<int32_t>(m.positions.size());
  m.positions.push_back({0, -kSphereRadius, 0});
  auto ring = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({{0, ring(1, j), ring(1, j + 1)}});
    for (int i = 1; i + 1 < bands; ++i) {
      m.triangles.push_back({{ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)}});
      m.triangles.push_back({{ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)}});
    }
    m.triangles.push_back({{south, ring(bands - 1, j + 1), ring(bands - 1, j)}});
  }
  // Outward winding, decided per face rather than by the index order above.
  for (geom::Tri& t : m.triangles) {
    const geom::Vec3d a = m.positions[t.v[0]], b = m.positions[t.v[1]], c = m.positions[t.v[2]];
    const geom::Vec3d u = b - a, v = c - a;
    const geom::Vec3d n = {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    if (n.x * (a.x + b.x + c.x) + n.y * (a.y + b.y + c.y) + n.z * (a.z + b.z + c.z) < 0)
      std::swap(t.v[1], t.v[2]);
  }
  return m;
}

/// Writes `m` translated by `dx` along x as OBJ (nine significant digits: copies of a file
/// read back bit for bit the same).
void write_obj(const fs::path& path, const mesh::Mesh& m, double dx) {
  std::string out;
  out.reserve(m.positions.size() * 40 + m.triangles.size() * 24);
  char line[96];
  for (const geom::Vec3d& p : m.positions) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x + dx, p.y, p.z);
    out += line;
  }
  for (const geom::Tri& t : m.triangles) {
    std::snprintf(line, sizeof line, "f %d %d %d\n", t.v[0] + 1, t.v[1] + 1, t.v[2] + 1);
    out += line;
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw InternalError("bench scene: cannot write " + path.string());
  const bool written = std::fwrite(out.data(), 1, out.size(), f) == out.size();
  if (std::fclose(f) != 0 || !written)
    throw InternalError("bench scene: cannot write " + path.string());
}

fs::path numbered(const fs::path& dir, const std::string& prefix, int64_t number) {
  char name[64];
  std::snprintf(name, sizeof name, "%s.%04lld.obj", prefix.c_str(), static_cast<long long>(number));
  return dir / name;
}

// ---------------------------------------------------------------------------------------------
// The scenes.

struct SceneCase {
  std::string name;
  scene::Scene scene;
  std::string frames;  ///< --frames selection: the kept cloth frames
};

scene::ObjectSpec cloth_object(const std::string& sequence, bool with_obstacle) {
  scene::ObjectSpec cloth;
  cloth.name = "cloth";
  cloth.sequence = sequence;
  if (with_obstacle) cloth.against = {"obstacle"};
  return cloth;
}

scene::ObjectSpec obstacle_object(const std::string& sequence, bool self) {
  scene::ObjectSpec obstacle;
  obstacle.name = "obstacle";
  obstacle.sequence = sequence;
  obstacle.role = scene::Role::obstacle;
  obstacle.self = self;
  return obstacle;
}

/// Writes the obstacle files and the frozen frames into `dir`, beside the generated cloth
/// `frames` (the last of the simulated frames in `cloth_dir`), and returns the scenes in table
/// order.
std::vector<SceneCase> make_cases(const std::vector<fs::path>& frames, const fs::path& cloth_dir,
                                  const mesh::Mesh& sphere, const fs::path& dir) {
  std::vector<int64_t> numbers;
  for (const fs::path& f : frames) numbers.push_back(seq::frame_number_from_name(f));
  const std::string selection =
      std::to_string(numbers.front()) + "-" + std::to_string(numbers.back());
  const std::string cloth = cloth_dir.string();  // the generator's frames, these selected

  const fs::path still = dir / "obstacle.obj";
  write_obj(still, sphere, 0);
  const fs::path moving = dir / "moving";
  const fs::path frozen = dir / "frozen";
  fs::create_directories(moving);
  fs::create_directories(frozen);
  for (size_t i = 0; i < numbers.size(); ++i) {
    write_obj(numbered(moving, "obstacle", numbers[i]), sphere,
              kStepPerFrame * static_cast<double>(i));
    // The frozen frames: every object's file a copy of one frame (the last, the most folded).
    fs::copy_file(frames.back(), numbered(frozen, "cloth", numbers[i]));
    fs::copy_file(still, numbered(frozen, "obstacle", numbers[i]));
  }
  const std::string moving_pattern = (moving / "obstacle.%04d.obj").string();
  std::vector<SceneCase> cases;
  cases.push_back({"cloth alone", {{cloth_object(cloth, false)}}, selection});
  cases.push_back({"still obstacle",
                   {{cloth_object(cloth, true), obstacle_object(still.string(), false)}},
                   selection});
  cases.push_back({"moving obstacle",
                   {{cloth_object(cloth, true), obstacle_object(moving_pattern, false)}},
                   selection});
  cases.push_back({"obstacle self too",
                   {{cloth_object(cloth, true), obstacle_object(moving_pattern, true)}},
                   selection});
  cases.push_back({"frozen frame",
                   {{cloth_object((frozen / "cloth.%04d.obj").string(), true),
                     obstacle_object((frozen / "obstacle.%04d.obj").string(), false)}},
                   selection});
  return cases;
}

// ---------------------------------------------------------------------------------------------
// One scene on one backend.

struct ObjectRow {
  std::string name;
  int32_t triangles = 0;
  bool still = false;
  double build = 0;  ///< ms, the first frame
  double refit = 0;  ///< ms, median over the timed frames
  int moved = 0;     ///< timed frames in which it moved
  int rebuilt = 0;   ///< timed frames in which its tree was rebuilt (tree quality)
};

struct CheckRow {
  std::string name;
  double ms = 0;  ///< median over the timed frames
  int64_t pairs = 0;
  int reused = 0;  ///< timed frames whose pairs were kept
};

/// What the tables need of one frame's result.
struct FrameOutcome {
  int64_t pairs = 0;
  std::vector<detect::PartOutcome> parts;
  std::vector<detect::CheckOutcome> checks;
};

struct Row {
  std::string backend;
  std::string scene;
  int objects = 0;
  int timed = 0;
  double set = 0;    ///< ms: Checker::set_scene (the topology: edges, neighbours; uploaded)
  double first = 0;  ///< ms: the first frame checked (every tree built)
  double check = 0;  ///< ms per later frame, median
  double read = 0;   ///< ms per frame, median
  double loop = 0;   ///< ms per frame of `snag check`'s loop, median
  int64_t pairs = 0;
  int reused = 0;      ///< checks reused over the timed frames
  int check_runs = 0;  ///< checks over the timed frames
  std::vector<ObjectRow> object_rows;
  std::vector<CheckRow> check_rows;
};

/// The frame loop of `snag check` on `scene` (reading ahead, checking, penetration, records
/// made and dropped): milliseconds between consecutive frames' records, and each frame's pairs.
std::vector<double> time_frame_loop(const scene::ResolvedScene& scene, const std::string& backend,
                                    int threads, int device, std::vector<int64_t>& pairs) {
  const std::unique_ptr<detect::Checker> checker =
      make_bench_checker(backend, checker_threads_for(threads, backend == "cuda"), device);
  SequenceSettings settings;
  settings.threads = threads;
  settings.gpu = checker->backend_name() == "cuda";
  // A scene of one object reports as a single mesh, as `snag check` on a sequence does.
  const bool scene_report = scene.objects.size() > 1;
  report::Inputs inputs;
  for (const scene::ResolvedObject& o : scene.objects) {
    if (!scene_report) break;
    report::ObjectInput input;
    input.name = o.spec.name;
    input.role = o.spec.role == scene::Role::cloth ? "cloth" : "obstacle";
    input.sequence = o.spec.sequence;
    input.still = o.still;
    inputs.objects.push_back(input);
  }
  std::vector<double> intervals;
  pairs.clear();
  auto last = Clock::now();
  check_scene(
      scene, *checker, settings, scene_report, inputs,
      [&](report::FrameRecord&& record) {
        pairs.push_back(static_cast<int64_t>(record.pairs.size()));
        intervals.push_back(ms_since(last));
        last = Clock::now();
      },
      [](const std::string& warning) { std::cerr << "snag bench scene: " << warning << "\n"; });
  return intervals;
}

Row run_scene(const SceneCase& c, const std::string& backend, const BenchSceneOptions& o,
              int threads) {
  std::cerr << "snag bench scene: " << backend << ": " << c.name << "\n";
  const scene::ResolvedScene resolved = scene::resolve_scene(c.scene, c.frames);
  const size_t frame_count = resolved.frames.size();
  const size_t first_timed = static_cast<size_t>(1 + o.warmup);
  if (frame_count <= first_timed)
    throw InternalError("bench scene: " + std::to_string(frame_count) + " frames for " +
                        std::to_string(first_timed) + " untimed");

  // Every frame read beforehand, one thread, as `snag check` reads it (a still object once,
  // when the reader is made; the others with FrameReaders that parse positions only).
  const scene::SceneReader reader(resolved);
  std::vector<io::FrameReader> readers = reader.make_readers();
  std::vector<scene::SceneFrame> frames;
  std::vector<double> read_ms;
  for (size_t i = 0; i < frame_count; ++i) {
    const auto started = Clock::now();
    frames.push_back(reader.read(i, readers));
    read_ms.push_back(ms_since(started));
  }

  // Checked from memory: which objects moved (compared as `snag check` does) and
  // Checker::check, each next frame staged on a GPU.
  const std::unique_ptr<detect::Checker> checker = make_bench_checker(backend, threads, o.device);
  const bool gpu = checker->backend_name() == "cuda";
  auto set_scene = [&](detect::Checker& c) {
    const scene::SceneFrame& f = frames.front();
    const auto started = Clock::now();
    c.set_scene(f.mesh.triangles, static_cast<int32_t>(f.mesh.positions.size()), f.layout,
                resolved.checks);
    return ms_since(started);
  };
  std::vector<double> set_ms = {set_scene(*checker)};
  std::vector<double> check_ms;
  std::vector<FrameOutcome> outcomes;
  for (size_t i = 0; i < frame_count; ++i) {
    const scene::SceneFrame& f = frames[i];
    const auto started = Clock::now();
    std::vector<uint8_t> moved, next_moved;
    std::span<const geom::Vec3d> next;
    if (i > 0) moved = moved_between(frames[i - 1], f);
    if (gpu && i + 1 < frame_count) {
      next = frames[i + 1].mesh.positions;
      next_moved = moved_between(f, frames[i + 1]);
    }
    detect::FrameResult r =
        checker->check({f.mesh.positions, moved, next, next_moved, /*finite=*/true});
    check_ms.push_back(ms_since(started));
    outcomes.push_back(
        {static_cast<int64_t>(r.pairs.size()), std::move(r.parts), std::move(r.checks)});
  }

  // The first frame is one sample, at the mercy of page faults in fresh buffers: it is taken
  // again on fresh checkers and the median kept, per object too.
  std::vector<double> first_ms = {check_ms.front()};
  std::vector<std::vector<double>> build_ms(resolved.objects.size());
  for (size_t p = 0; p < build_ms.size(); ++p)
    build_ms[p].push_back(1e3 * outcomes.front().parts[p].build_seconds);
  for (int k = 1; k < kFirstFrameSamples; ++k) {
    const std::unique_ptr<detect::Checker> fresh = make_bench_checker(backend, threads, o.device);
    set_ms.push_back(set_scene(*fresh));
    const auto started = Clock::now();
    const detect::FrameResult r = fresh->check(frames.front().mesh.positions);
    first_ms.push_back(ms_since(started));
    for (size_t p = 0; p < build_ms.size(); ++p)
      build_ms[p].push_back(1e3 * r.parts[p].build_seconds);
  }

  // The same frames through `snag check`'s loop, which must find the same pairs.
  std::vector<int64_t> loop_pairs;
  const std::vector<double> loop_ms =
      time_frame_loop(resolved, backend, threads, o.device, loop_pairs);
  for (size_t i = 0; i < frame_count; ++i)
    if (i >= loop_pairs.size() || loop_pairs[i] != outcomes[i].pairs)
      throw InternalError("bench scene: " + c.name + ", frame " + std::to_string(i) +
                          ": snag check's loop found " +
                          (i < loop_pairs.size() ? std::to_string(loop_pairs[i]) : "no") +
                          " pairs, checking from memory " + std::to_string(outcomes[i].pairs));

  Row row;
  row.backend = backend;
  row.scene = c.name;
  row.objects = static_cast<int>(resolved.objects.size());
  row.timed = static_cast<int>(frame_count - first_timed);
  row.set = median(set_ms);
  row.first = median(first_ms);
  auto timed_median = [&](auto value) {
    std::vector<double> v;
    for (size_t i = first_timed; i < frame_count; ++i) v.push_back(value(i));
    return median(v);
  };
  row.check = timed_median([&](size_t i) { return check_ms[i]; });
  row.read = timed_median([&](size_t i) { return read_ms[i]; });
  row.loop = timed_median([&](size_t i) { return loop_ms[i]; });
  row.pairs = outcomes.back().pairs;
  for (size_t i = first_timed; i < frame_count; ++i)
    for (const detect::CheckOutcome& k : outcomes[i].checks) {
      row.reused += k.reused;
      ++row.check_runs;
    }

  for (size_t p = 0; p < resolved.objects.size(); ++p) {
    ObjectRow object;
    object.name = resolved.objects[p].spec.name;
    object.triangles =
        frames.front().layout.triangle_begin[p + 1] - frames.front().layout.triangle_begin[p];
    object.still = resolved.objects[p].still;
    object.build = median(build_ms[p]);
    object.refit = timed_median([&](size_t i) { return 1e3 * outcomes[i].parts[p].refit_seconds; });
    for (size_t i = first_timed; i < frame_count; ++i) {
      object.moved += outcomes[i].parts[p].moved;
      object.rebuilt += outcomes[i].parts[p].rebuilt;
    }
    row.object_rows.push_back(object);
  }
  for (size_t k = 0; k < resolved.checks.size(); ++k) {
    const detect::PartCheck pc = resolved.checks[k];
    CheckRow check;
    check.name = resolved.objects[pc.a].spec.name +
                 (pc.self() ? " self" : " x " + resolved.objects[pc.b].spec.name);
    check.ms = timed_median([&](size_t i) { return 1e3 * outcomes[i].checks[k].seconds; });
    check.pairs = outcomes.back().checks[k].pairs;
    for (size_t i = first_timed; i < frame_count; ++i) check.reused += outcomes[i].checks[k].reused;
    row.check_rows.push_back(check);
  }
  return row;
}

/// Each scene's first frame checked once, untimed, so that the first frames timed next are the
/// scene's cost, not the process's first use of the thread pool, the allocator or the device.
void warm_up(const std::vector<SceneCase>& cases, const std::string& backend, int threads,
             int device) {
  for (const SceneCase& c : cases) {
    const scene::ResolvedScene resolved = scene::resolve_scene(c.scene, c.frames);
    const scene::SceneReader reader(resolved);
    std::vector<io::FrameReader> readers = reader.make_readers();
    const scene::SceneFrame f = reader.read(0, readers);
    const std::unique_ptr<detect::Checker> checker = make_bench_checker(backend, threads, device);
    checker->set_scene(f.mesh.triangles, static_cast<int32_t>(f.mesh.positions.size()), f.layout,
                       resolved.checks);
    checker->check(f.mesh.positions);
  }
}

// ---------------------------------------------------------------------------------------------
// The tables.

/// Fixed-width columns; the scene names fill the second. "reused" is checks reused out of
/// checks over the timed frames.
void print_tables(const std::vector<Row>& rows, const std::vector<std::string>& skipped) {
  std::printf("%-8s %-18s %7s %8s %8s %8s %8s %10s %8s %8s\n", "backend", "scene", "objects", "set",
              "first", "check", "read", "snag check", "pairs", "reused");
  for (const Row& r : rows) {
    const std::string reused = std::to_string(r.reused) + "/" + std::to_string(r.check_runs);
    std::printf("%-8s %-18s %7d %8.3f %8.3f %8.3f %8.3f %10.3f %8lld %8s\n", r.backend.c_str(),
                r.scene.c_str(), r.objects, r.set, r.first, r.check, r.read, r.loop,
                static_cast<long long>(r.pairs), reused.c_str());
  }
  for (const std::string& s : skipped) std::printf("%s\n", s.c_str());

  std::printf(
      "\nPer object: build = its tree on the first frame (median of %d fresh checkers), ms; "
      "refit =\nmedian per timed frame, ms (0: it did not move; -: on the GPU a moved object's "
      "refit is\nqueued with the frame's degenerate-face scan, not timed apart); moved, rebuilt "
      "= timed\nframes in which it moved, in which its tree was rebuilt (its quality had "
      "degraded)\n",
      kFirstFrameSamples);
  std::printf("%-8s %-18s %-9s %9s %5s %9s %9s %7s %7s\n", "backend", "scene", "object",
              "triangles", "still", "build", "refit", "moved", "rebuilt");
  for (const Row& r : rows)
    for (const ObjectRow& o : r.object_rows) {
      const std::string moved = std::to_string(o.moved) + "/" + std::to_string(r.timed);
      const std::string rebuilt = std::to_string(o.rebuilt) + "/" + std::to_string(r.timed);
      char refit[32];
      if (r.backend == "cuda" && o.moved > 0)
        std::snprintf(refit, sizeof refit, "-");
      else
        std::snprintf(refit, sizeof refit, "%.3f", o.refit);
      std::printf("%-8s %-18s %-9s %9d %5s %9.3f %9s %7s %7s\n", r.backend.c_str(), r.scene.c_str(),
                  o.name.c_str(), o.triangles, o.still ? "yes" : "no", o.build, refit,
                  moved.c_str(), rebuilt.c_str());
    }

  std::printf(
      "\nPer check: ms = traversal and filtered narrow phase, median per timed frame (0 when "
      "its\npairs were reused); pairs on the last frame; reused = timed frames whose pairs "
      "were the\nprevious frame's, taken without checking\n");
  std::printf("%-8s %-18s %-18s %9s %8s %7s\n", "backend", "scene", "check", "ms", "pairs",
              "reused");
  for (const Row& r : rows)
    for (const CheckRow& k : r.check_rows) {
      const std::string reused = std::to_string(k.reused) + "/" + std::to_string(r.timed);
      std::printf("%-8s %-18s %-18s %9.3f %8lld %7s\n", r.backend.c_str(), r.scene.c_str(),
                  k.name.c_str(), k.ms, static_cast<long long>(k.pairs), reused.c_str());
    }
}

}  // namespace

CLI::App* add_bench_scene_command(CLI::App& bench, BenchSceneOptions& o) {
  CLI::App* cmd = bench.add_subcommand(
      "scene",
      "What a scene costs per frame: a cloth alone, with a still, a moving and a self-checked "
      "obstacle, and a frozen frame, on the CPU and the GPU");
  cmd->add_option("--size", o.size, "Triangles of the generated cloth")
      ->type_name("T")
      ->check(kPositiveCount)
      ->capture_default_str();
  cmd->add_option("--obstacle-size", o.obstacle_size, "Triangles of the sphere obstacle (about)")
      ->type_name("T")
      ->check(kPositiveCount)
      ->capture_default_str();
  cmd->add_option("--frames", o.frames, "Timed frames per scene, after the first and the warm-up")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  cmd->add_option("--warmup", o.warmup, "Untimed frames per scene after the first")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  cmd->add_option("--backend", o.backend,
                  "cpu, cuda, or both (the CPU, and the GPU where snag has the CUDA backend and "
                  "a device that can run it; else the GPU's row says why it was skipped)")
      ->type_name("NAME")
      ->check(CLI::IsMember({"cpu", "cuda", "both"}))
      ->capture_default_str();
  cmd->add_option("--generator", o.generator,
                  "The snag-cloth sample generator (default: beside snag, in the build tree, or "
                  "on PATH)")
      ->type_name("PATH");
  cmd->add_option("-j,--threads", o.threads, "CPU worker threads; 0 uses every core")
      ->type_name("N")
      ->check(kThreadCount)
      ->capture_default_str();
  cmd->add_option("--device", o.device, "CUDA device, numbered from 0")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  return cmd;
}

int run_bench_scene(const BenchSceneOptions& o) {
  const int threads = thread_count(o.threads);
  // The backends, each checked before any work: a GPU asked for and missing is an error, one
  // merely possible (both) a note under the table.
  std::vector<std::string> backends;
  std::vector<std::string> skipped;
  if (o.backend != "cuda") backends.push_back("cpu");
  if (o.backend == "both" && !cuda_built()) {
    skipped.push_back("cuda     skipped: this snag was built without the CUDA backend");
  } else if (std::string why;
             o.backend == "both" && resolve_auto_backend(o.device, &why) != "cuda") {
    skipped.push_back("cuda     skipped: " + (why.empty() ? std::string("no CUDA device") : why));
  } else if (o.backend != "cpu") {
    make_backend("cuda", threads, o.device);  // throws DeviceUnavailable, saying why
    backends.push_back("cuda");
  }

  ScratchDir scratch;
  // The first frame, the warm-up and the timed frames, once the cloth has folded on the sphere.
  const int keep = 1 + o.warmup + o.frames;
  const fs::path cloth_dir = scratch.path() / "cloth";
  const std::vector<fs::path> cloth =
      generated_cloth(o.generator, o.size, settle_frames, keep, cloth_dir);
  if (cloth.size() != static_cast<size_t>(keep))
    throw InternalError("bench scene: the generator wrote " + std::to_string(cloth.size()) +
                        " frames, " + std::to_string(keep) + " expected");
  const auto cloth_triangles = static_cast<int>(io::read_mesh(cloth.front()).triangles.size());
  const mesh::Mesh sphere = uv_sphere(o.obstacle_size);
  const std::vector<SceneCase> cases = make_cases(cloth, cloth_dir, sphere, scratch.path());

  std::vector<Row> rows;
  for (const std::string& backend : backends) {
    warm_up(cases, backend, threads, o.device);
    for (const SceneCase& c : cases) rows.push_back(run_scene(c, backend, o, threads));
  }

  std::printf(
      "snag bench scene: a cloth of %d triangles falling on a sphere of %zu triangles (radius "
      "%.2f;\nmoving: %.1f mm along x a frame); %d threads; milliseconds per frame, medians over "
      "%d timed\nframes after the first and %d warm-up\n",
      cloth_triangles, sphere.triangles.size(), kSphereRadius, kStepPerFrame * 1e3, threads,
      o.frames, o.warmup);
  std::printf(
      "set        = Checker::set_scene: the scene's topology (edges, neighbour pairs; on a GPU\n"
      "             its upload queued), made once per topology\n"
      "first      = the first frame checked: every tree built (on a GPU, positions uploaded)\n"
      "             set and first: medians of %d fresh checkers\n"
      "check      = a later frame from memory: which objects moved (compared bit for bit, as\n"
      "             snag check does) and Checker::check\n"
      "read       = reading the frame's files, one thread (a still object was read once, "
      "before)\n"
      "snag check = its frame loop: reading ahead, checking, penetration (the sphere is "
      "closed:\n"
      "             measured whenever the cloth or the sphere moved), records made, not "
      "written\n"
      "reused     = checks whose pairs were the previous frame's, of the checks of the timed "
      "frames\n\n",
      kFirstFrameSamples);
  print_tables(rows, skipped);
  return 0;
}

}  // namespace snag::cli
