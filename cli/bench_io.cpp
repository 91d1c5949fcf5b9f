// `snag bench io`: how fast frames are read, and whether checking a sequence keeps up with
// reading it. Three tables, in one run:
//   readers   - bytes per second reading the same frames with snag's readers (a frame parsed
//               in full, and frames read in sequence, where only positions are parsed), with
//               tinyobjloader and with assimp, next to read() into memory (the floor);
//   sequence  - per backend, the time of `snag check` on a whole sequence next to reading
//               alone and checking alone, all with the same thread count, where the loop's
//               thread spent its time, and the CPU time of each with the loop's floor (its
//               CPU time over the machine's cores);
//   memory    - the peak resident memory of `snag check` on a short and on a long sequence.
// A benchmark, not a test: it prints the tables and fails only when something cannot run.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fcntl.h>
#include <unistd.h>
#include <assimp/Importer.hpp>

#ifdef SNAG_HAVE_TINYOBJLOADER
#include <tiny_obj_loader.h>
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "backend_factory.h"
#include "bench_support.h"
#include "check_sequence.h"
#include "commands.h"
#include "snag/cpu_time.h"
#include "snag/error.h"
#include "snag/io/assimp_reader.h"
#include "snag/io/read_mesh.h"
#include "snag/report/stream.h"
#include "snag/seq/prefetch.h"
#include "snag/seq/sequence.h"
#include "snag/threads.h"

namespace snag::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A phase's wall time and the CPU time the process spent in it, from construction to stop().
class PhaseClock {
 public:
  struct Times {
    double wall = 0;
    double cpu = 0;
  };
  Times stop() const { return {seconds_since(wall_), process_cpu_seconds() - cpu_}; }

 private:
  Clock::time_point wall_ = Clock::now();
  double cpu_ = process_cpu_seconds();
};

uint64_t total_bytes(const std::vector<fs::path>& files) {
  uint64_t bytes = 0;
  for (const fs::path& f : files) bytes += fs::file_size(f);
  return bytes;
}

// ---------------------------------------------------------------------------------------------
// Files in other encodings, written from the generated OBJ frames, so that every reader reads
// the same frames.

void write_binary_ply(const fs::path& path, const mesh::Mesh& m) {
  std::string out =
      "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.positions.size()) +
      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
      std::to_string(m.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "the bench writes little-endian PLY");
  for (const geom::Vec3d& p : m.positions) {
    const float xyz[3] = {static_cast<float>(p.x), static_cast<float>(p.y),
                          static_cast<float>(p.z)};
    out.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  }
  for (const geom::Tri& t : m.triangles) {
    out.push_back(3);
    out.append(reinterpret_cast<const char*>(t.v), sizeof t.v);
  }
  std::ofstream(path, std::ios::binary) << out;
}

void write_ascii_ply(const fs::path& path, const mesh::Mesh& m) {
  std::string out = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(m.positions.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(m.triangles.size()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  char line[128];
  for (const geom::Vec3d& p : m.positions) {
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", p.x, p.y, p.z);
    out += line;
  }
  for (const geom::Tri& t : m.triangles) {
    std::snprintf(line, sizeof line, "3 %d %d %d\n", t.v[0], t.v[1], t.v[2]);
    out += line;
  }
  std::ofstream(path, std::ios::binary) << out;
}

/// The frames of `files` written again as `ext` ("ply" binary or "ascii.ply") into `dir`.
std::vector<fs::path> converted(const std::vector<fs::path>& files, const fs::path& dir,
                                bool binary) {
  fs::create_directories(dir);
  std::vector<fs::path> out;
  for (size_t i = 0; i < files.size(); ++i) {
    const mesh::Mesh m = io::read_mesh(files[i]);
    char name[32];
    std::snprintf(name, sizeof name, "frame.%04zu.ply", i + 1);
    out.push_back(dir / name);
    if (binary)
      write_binary_ply(out.back(), m);
    else
      write_ascii_ply(out.back(), m);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Readers.

/// One way of reading a frame file; returns something derived from what it read so that the
/// work cannot be optimized away.
struct Reader {
  std::string name;
  bool obj_only = false;
  /// Reads every file once, in order (a fresh reader state per pass, as a new sequence).
  std::function<size_t(const std::vector<fs::path>&)> read_all;
};

/// read() of each file into one reused buffer: the page cache copied into memory, the floor
/// under every parser.
size_t read_into_memory(const std::vector<fs::path>& files) {
  static thread_local std::vector<char> buffer;
  size_t sum = 0;
  for (const fs::path& f : files) {
    const int fd = ::open(f.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(f.string(), 0, "cannot open");
    const size_t size = fs::file_size(f);
    if (buffer.size() < size) buffer.resize(size);
    size_t done = 0;
    while (done < size) {
      const ssize_t got = ::read(fd, buffer.data() + done, size - done);
      if (got <= 0) break;
      done += static_cast<size_t>(got);
    }
    ::close(fd);
    sum += done + static_cast<unsigned char>(buffer[done / 2]);
  }
  return sum;
}

std::vector<Reader> readers() {
  std::vector<Reader> list;
  list.push_back({"read() only", false, read_into_memory});
  list.push_back({"snag, each frame in full", false, [](const std::vector<fs::path>& files) {
                    size_t sum = 0;
                    for (const fs::path& f : files) sum += io::read_mesh(f).triangles.size();
                    return sum;
                  }});
  list.push_back({"snag, in sequence", false, [](const std::vector<fs::path>& files) {
                    io::FrameReader reader;
                    size_t sum = 0;
                    for (const fs::path& f : files) sum += reader.read(f).triangles.size();
                    return sum;
                  }});
#ifdef SNAG_HAVE_TINYOBJLOADER
  list.push_back({"tinyobjloader", true, [](const std::vector<fs::path>& files) {
                    size_t sum = 0;
                    tinyobj::ObjReaderConfig config;
                    config.triangulate = true;
                    config.vertex_color = false;
                    for (const fs::path& f : files) {
                      tinyobj::ObjReader reader;
                      if (!reader.ParseFromFile(f.string(), config))
                        throw InputError(f.string(), 0, "tinyobjloader: " + reader.Error());
                      sum += reader.GetAttrib().vertices.size();
                    }
                    return sum;
                  }});
#endif
  list.push_back({"assimp", false, [](const std::vector<fs::path>& files) {
                    size_t sum = 0;
                    for (const fs::path& f : files) {
                      // Triangulation only: the lightest setting that gives triangles (snag's
                      // own assimp path also joins identical vertices, which costs more). Read,
                      // checked, then triangulated, as snag's path does: libassimp 5.2 misreads
                      // some binary PLY files, and triangulating those aborts the process.
                      Assimp::Importer importer;
                      const aiScene& scene =
                          io::import_checked(importer, f, 0, aiProcess_Triangulate);
                      for (unsigned i = 0; i < scene.mNumMeshes; ++i)
                        sum += scene.mMeshes[i]->mNumVertices;
                    }
                    return sum;
                  }});
  return list;
}

struct ReaderCase {
  std::string name;
  bool is_obj = false;
  std::vector<fs::path> files;
};

/// Megabytes per second of each reader on each case: the median over `passes` passes.
void readers_table(const std::vector<ReaderCase>& cases, int passes) {
  const std::vector<Reader> list = readers();
  std::printf(
      "\nReaders: one thread, files in the page cache; MB/s, median of %d passes over "
      "each case's frames\n",
      passes);
  std::printf("%-26s %7s %9s", "case", "frames", "MB/frame");
  for (const Reader& r : list) std::printf(" %13.13s", r.name.c_str());
  std::printf("\n");
  std::vector<std::string> misread;  // a peer that cannot read a case's files: why
  for (const ReaderCase& c : cases) {
    const double bytes = static_cast<double>(total_bytes(c.files));
    std::printf("%-26s %7zu %9.2f", c.name.c_str(), c.files.size(), bytes / c.files.size() / 1e6);
    std::fflush(stdout);
    for (const Reader& r : list) {
      if (r.obj_only && !c.is_obj) {
        std::printf(" %13s", "-");
        continue;
      }
      try {
        r.read_all(c.files);  // warm-up: page cache, allocator, thread buffers
      } catch (const InputError& e) {
        // snag's readers read every frame (checked before this table); a peer that cannot is
        // a finding, not the end of the bench.
        if (r.name.rfind("snag", 0) == 0) throw;
        std::printf(" %13s", "misread");
        misread.push_back(r.name + " on " + c.name + ": " + e.what());
        continue;
      }
      std::vector<double> rates;
      for (int pass = 0; pass < passes; ++pass) {
        const auto started = Clock::now();
        volatile size_t sink = r.read_all(c.files);
        (void)sink;
        rates.push_back(bytes / seconds_since(started) / 1e6);
      }
      // Whole MB/s, but a rate under 10 (a sanitizer's build, a slow disk) keeps a digit or
      // three after the point rather than printing 0.
      const double rate = median(rates);
      std::printf(" %13.*f", rate >= 10 ? 0 : rate >= 0.1 ? 1 : 3, rate);
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  for (const std::string& why : misread) std::printf("misread: %s\n", why.c_str());
}

// ---------------------------------------------------------------------------------------------
// A whole sequence: `snag check` next to reading alone and checking alone.

/// `snag check`'s frame loop (reading ahead, checking, writing reports into `out`).
struct CheckCommandRun {
  PhaseClock::Times times;
  int readers = 0;         ///< reader threads it used
  int64_t pairs = 0;       ///< over every frame
  LoopTimes loop;          ///< where its loop's thread spent the time
  double reports_cpu = 0;  ///< CPU seconds in the report stream's own threads
};

struct SequenceRow {
  std::string backend;
  PhaseClock::Times read;   ///< every frame read by `threads` reader threads, nothing checked
  PhaseClock::Times check;  ///< every frame checked from memory
  int64_t pairs = 0;        ///< checking from memory found
  CheckCommandRun both;     ///< the frame loop of `snag check`, reports written

  double larger_wall() const { return std::max(read.wall, check.wall); }
};

/// f() on a thread of its own, its exception rethrown here. Checking alone and the check
/// command each run this way: OpenMP keeps a pool of threads per thread that opens parallel
/// regions, and a pool of `threads` workers left by checking alone would spin beside the check
/// command's own, smaller one (its checker leaves cores to the readers and the report writer).
template <class F>
auto on_own_thread(F&& f) {
  decltype(f()) result{};
  std::exception_ptr error;
  std::thread thread([&] {
    try {
      result = f();
    } catch (...) {
      error = std::current_exception();
    }
  });
  thread.join();
  if (error) std::rethrow_exception(error);
  return result;
}

/// Reading every frame with `readers` threads, as `snag check` reads them.
PhaseClock::Times time_reading(const std::vector<seq::Frame>& frames, int readers) {
  const PhaseClock clock;
  std::vector<io::FrameReader> per_thread(static_cast<size_t>(readers));
  seq::FramePrefetcher prefetcher(frames, readers, 2 * readers,
                                  [&](const seq::Frame& f, int reader) {
                                    return per_thread[static_cast<size_t>(reader)].read(f.path);
                                  });
  while (prefetcher.next()) {
  }
  return clock.stop();
}

/// Checking every frame from memory (read beforehand), each next frame staged.
PhaseClock::Times time_checking(const std::vector<seq::Frame>& frames, const std::string& backend,
                                int threads, int device, int64_t& pairs) {
  std::vector<mesh::Mesh> meshes;
  io::FrameReader reader;
  for (const seq::Frame& f : frames) meshes.push_back(reader.read(f.path));
  const std::unique_ptr<detect::Checker> checker = make_bench_checker(backend, threads, device);
  checker->set_triangles(meshes.front().triangles,
                         static_cast<int32_t>(meshes.front().positions.size()));
  checker->check(meshes.front().positions);  // warm-up: the first build, the buffers
  pairs = 0;
  const PhaseClock clock;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const std::span<const geom::Vec3d> next =
        i + 1 < meshes.size() ? std::span<const geom::Vec3d>(meshes[i + 1].positions)
                              : std::span<const geom::Vec3d>();
    pairs += static_cast<int64_t>(checker->check(meshes[i].positions, next).pairs.size());
  }
  return clock.stop();
}

CheckCommandRun time_check_command(const std::vector<seq::Frame>& frames,
                                   const std::string& backend, int threads, int device,
                                   const fs::path& out) {
  CheckCommandRun run;
  const std::unique_ptr<detect::Checker> checker =
      make_bench_checker(backend, checker_threads_for(threads, backend == "cuda"), device);
  {  // warm-up, as for checking alone: the device and its buffers
    const mesh::Mesh first = io::read_mesh(frames.front().path);
    checker->set_triangles(first.triangles, static_cast<int32_t>(first.positions.size()));
    checker->check(first.positions);
  }
  SequenceSettings settings;
  settings.threads = threads;
  settings.gpu = checker->backend_name() == "cuda";
  settings.times = &run.loop;
  run.readers = readers_for(settings.threads, settings.gpu);
  const PhaseClock clock;
  report::ReportStream stream(out, SNAG_VERSION, {}, {}, threads);
  report::Inputs inputs;
  check_sequence(
      frames, *checker, settings, inputs,
      [&](report::FrameRecord&& record) { stream.add(std::move(record)); },
      [](const std::string&) {});
  const report::Summary summary =
      stream.finish(inputs, checker->build_count(), checker->rebuild_count(), 0);
  run.times = clock.stop();
  run.pairs = summary.pairs;
  run.reports_cpu = stream.cpu_seconds();
  return run;
}

void sequence_table(const std::string& name, const std::vector<seq::Frame>& frames,
                    const std::vector<std::string>& backends, int threads, int device,
                    const fs::path& scratch) {
  std::vector<SequenceRow> rows;
  for (const std::string& backend : backends) {
    std::cerr << "snag bench io: " << name << ": " << backend << "\n";
    SequenceRow row;
    row.backend = backend;
    row.read = time_reading(frames, threads);
    row.check =
        on_own_thread([&] { return time_checking(frames, backend, threads, device, row.pairs); });
    row.both = on_own_thread(
        [&] { return time_check_command(frames, backend, threads, device, scratch / backend); });
    if (row.both.pairs != row.pairs)
      throw InternalError("bench io: snag check found " + std::to_string(row.both.pairs) +
                          " pairs, checking from memory " + std::to_string(row.pairs));
    // The loop's reports (~0.25 MB a frame of this cloth) go, and what is still being written
    // back from the page cache is written: neither is in the next row's times (a run whose
    // reports replaced an earlier run's paid ~20 ms on the H200's host for freeing them).
    std::error_code ignored;
    fs::remove_all(scratch / backend, ignored);
    ::sync();
    rows.push_back(row);
  }
  const double bytes = static_cast<double>(total_bytes([&] {
    std::vector<fs::path> files;
    for (const seq::Frame& f : frames) files.push_back(f.path);
    return files;
  }()));
  std::printf("\nSequence: %s, %zu frames, %.0f MB, %d threads; seconds for the whole sequence\n",
              name.c_str(), frames.size(), bytes / 1e6, threads);
  std::printf(
      "read = %d reader threads, nothing checked; check = every frame from memory; snag "
      "check = its frame\nloop (reading ahead on its reader threads, checking, writing the "
      "reports; %d threads in all on the\nCPU from 8 threads, readers on top below and on the "
      "GPU); readers = snag check's reader threads\n(read alone uses %d); MB/s = the "
      "sequence's bytes over snag check's time; / read, / larger =\nsnag check over read and "
      "over the larger of read and check; target: snag check within 10%% of\nthe larger of "
      "read and check on the CPU, of read on the GPU\n",
      threads, threads, threads);
  std::printf("%-8s %8s %9s %9s %11s %8s %10s %10s %8s\n", "backend", "readers", "read", "check",
              "snag check", "MB/s", "/ read", "/ larger", "pairs");
  for (const SequenceRow& r : rows) {
    const PhaseClock::Times& both = r.both.times;
    std::printf("%-8s %8d %9.3f %9.3f %11.3f %8.0f %9.2fx %9.2fx %8lld\n", r.backend.c_str(),
                r.both.readers, r.read.wall, r.check.wall, both.wall, bytes / both.wall / 1e6,
                both.wall / r.read.wall, both.wall / r.larger_wall(),
                static_cast<long long>(r.pairs));
  }
  std::printf(
      "\nWhere snag check's loop spent its time (seconds on the loop's thread): waiting = for the\n"
      "next frame, read and compared; preparing = a topology's set-up (weld, the checker's "
      "scene);\nchecking = Checker::check; recording = the frame's record; handing = to the "
      "report stream\n(on a GPU these two are beside the loop, on the recording thread, and "
      "behind = the loop's\nwait for them); starting = of waiting and preparing, until the "
      "first frame's check began;\nbeside the loop, on the preparing thread: comparing = each "
      "frame's faces and positions\nagainst the frame before's, staging = its positions copied "
      "into the GPU's pinned memory\n");
  std::printf("%-8s %9s %10s %9s %10s %9s %9s %9s %9s %10s %9s\n", "backend", "waiting",
              "preparing", "checking", "recording", "handing", "behind", "loop", "starting",
              "comparing", "staging");
  for (const SequenceRow& r : rows) {
    const LoopTimes& loop = r.both.loop;
    std::printf("%-8s %9.3f %10.3f %9.3f %10.3f %9.3f %9.3f %9.3f %9.3f %10.3f %9.3f\n",
                r.backend.c_str(), loop.waiting, loop.preparing, loop.checking, loop.recording,
                loop.handing, loop.behind, r.both.times.wall, loop.starting, loop.comparing,
                loop.staging);
  }
  std::printf(
      "\nchecking by the checker's stage clocks (seconds): scan = the degenerate-triangle scan "
      "(on a GPU\nalso the next frame's transfer queued, copied into pinned memory first when "
      "it was not\nstaged, and the wait for the work queued ahead); refit; build; traverse = "
      "traversal and narrow\nphase (on a GPU: the wait for the device); classify (on a GPU: the "
      "next frame's work queued,\nthe results decoded); exact = exact decisions and (--exact "
      "all) the confirmation; other =\nthe rest of checking\n");
  std::printf("%-8s %9s %9s %9s %9s %9s %9s %9s\n", "backend", "scan", "refit", "build", "traverse",
              "classify", "exact", "other");
  for (const SequenceRow& r : rows) {
    const LoopTimes& loop = r.both.loop;
    const detect::StageTimes& s = loop.stages;
    std::printf("%-8s %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f\n", r.backend.c_str(), s.scan,
                s.refit, s.build, s.traverse, s.classify, s.exact + s.confirm,
                loop.checking - s.total());
  }

  // The loop's floor: a schedule that spends the loop's CPU time on the machine's logical CPUs
  // takes at least that time over their count. Spinning and contention are in the CPU time
  // (the same work costs more CPU with more threads), so the floor of the work a loop must do
  // may be lower; still, a target far under the floor needs the loop to spend less, not to
  // overlap more.
  const unsigned cpus = std::max(1u, std::thread::hardware_concurrency());
  std::printf(
      "\nCPU seconds, every thread of the process (user and system, spinning included): "
      "reading alone,\nchecking alone, snag check, of which reports = the report stream's own "
      "threads (formatting,\nwriting) and rest = what is left beyond reading, checking and "
      "reports (comparing, preparing,\nrecording, spinning, and the difference between the "
      "loop's readers and checker threads and\nthose of reading and checking alone); busy = "
      "CPU / wall, the CPUs kept busy by reading alone\nand by snag check; floor = snag check's "
      "CPU over this machine's %u logical CPUs, the least wall\ntime of any schedule that "
      "spends as much CPU; / read, / larger = the floor over reading alone's\nwall time and "
      "over the larger of reading's and checking's\n",
      cpus);
  std::printf("%-8s %8s %8s %11s %8s %8s %10s %10s %8s %8s %9s\n", "backend", "read", "check",
              "snag check", "reports", "rest", "read busy", "snag busy", "floor", "/ read",
              "/ larger");
  for (const SequenceRow& r : rows) {
    const PhaseClock::Times& both = r.both.times;
    const double floor = both.cpu / cpus;
    std::printf("%-8s %8.3f %8.3f %11.3f %8.3f %8.3f %10.1f %10.1f %8.3f %7.2fx %8.2fx\n",
                r.backend.c_str(), r.read.cpu, r.check.cpu, both.cpu, r.both.reports_cpu,
                both.cpu - r.read.cpu - r.check.cpu - r.both.reports_cpu, r.read.cpu / r.read.wall,
                both.cpu / both.wall, floor, floor / r.read.wall, floor / r.larger_wall());
  }
}

// ---------------------------------------------------------------------------------------------
// Peak memory: `snag check` run as a child process, its peak resident set from wait4().

/// Peak resident memory in MiB of `snag check PATTERN --frames 1-N`, and its wall seconds.
std::pair<double, double> peak_memory_of_check(const std::string& pattern, int frames,
                                               const std::string& backend, int threads,
                                               const fs::path& out) {
  std::error_code ec;
  const std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  if (ec) throw InternalError("cannot find this executable to run `snag check`");
  const std::vector<std::string> args = {self,
                                         "check",
                                         pattern,
                                         "--frames",
                                         "1-" + std::to_string(frames),
                                         "--backend",
                                         backend,
                                         "--threads",
                                         std::to_string(threads),
                                         "--fail-on",
                                         "none",
                                         "--quiet",
                                         "--out",
                                         out.string()};
  const auto started = Clock::now();
  const ChildRun run = run_quietly(args);
  if (!run.started) throw InternalError("cannot run `snag check` (" + self + ")");
  if (run.exit_status < 0 || run.exit_status > 1)
    throw InternalError("`snag check` on " + std::to_string(frames) + " frames failed");
  return {run.peak_mib, seconds_since(started)};
}

void memory_table(const std::string& name, const std::string& pattern,
                  const std::vector<int>& lengths, const std::string& backend, int threads,
                  const fs::path& scratch) {
  std::printf(
      "\nMemory: `snag check` on the first N frames of %s (--backend %s, %d threads, "
      "reports written); peak resident set of the process\n",
      name.c_str(), backend.c_str(), threads);
  std::printf("%8s %12s %10s %14s\n", "frames", "peak MiB", "seconds", "vs the first");
  double first = 0;
  for (int n : lengths) {
    std::cerr << "snag bench io: memory, " << n << " frames\n";
    const auto [mib, seconds] = peak_memory_of_check(pattern, n, backend, threads,
                                                     scratch / ("memory-" + std::to_string(n)));
    if (first == 0) first = mib;
    std::printf("%8d %12.1f %10.2f %+13.1f\n", n, mib, seconds, mib - first);
  }
}

/// `count` frames named PREFIX.%04d.EXT in `dir`, copied cyclically from `files`: a long
/// sequence from a short simulation, every frame its own file.
std::vector<fs::path> cycled_copies(const std::vector<fs::path>& files, int count,
                                    const fs::path& dir) {
  fs::create_directories(dir);
  std::vector<fs::path> out;
  for (int i = 0; i < count; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "frame.%04d%s", i + 1,
                  files[static_cast<size_t>(i) % files.size()].extension().c_str());
    out.push_back(dir / name);
    fs::copy_file(files[static_cast<size_t>(i) % files.size()], out.back(),
                  fs::copy_options::overwrite_existing);
  }
  return out;
}

}  // namespace

CLI::App* add_bench_io_command(CLI::App& bench, BenchIoOptions& o) {
  CLI::App* io = bench.add_subcommand(
      "io",
      "Reading speed next to tinyobjloader and assimp, a whole sequence checked next to "
      "reading it alone, and peak memory against sequence length");
  io->add_option("--size", o.size, "Triangles of the generated cloth")
      ->type_name("T")
      ->check(kPositiveCount)
      ->capture_default_str();
  io->add_option("--frames", o.frames,
                 "Frames in the sequence (copies of the simulated frames, cyclically)")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  io->add_option("--passes", o.passes, "Timed passes over the frames per reader")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  io->add_option("--memory-frames", o.memory_frames,
                 "Sequence lengths whose peak memory is measured (0: none)")
      ->type_name("N,...")
      ->delimiter(',')
      ->check(kCount)
      ->capture_default_str();
  add_case_options(io, {nullptr, &o.data_dir, &o.inputs, &o.generator, &o.threads},
                   "its cloth-ball frames (big-endian PLY) are a reader case",
                   "read (and, from two frames on, check whole next to reading it)");
  io->add_option("--device", o.device, "CUDA device, numbered from 0")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  return io;
}

int run_bench_io(const BenchIoOptions& o) {
  ScratchDir scratch;
  const int threads = thread_count(o.threads);

  // The reader cases: the generated cloth as OBJ, binary PLY and ascii PLY, the shared data's
  // big-endian PLY, and every --input.
  std::vector<ReaderCase> cases;
  const fs::path data = data_folder(o.data_dir);
  std::vector<BenchCase> data_cases;
  add_data_case(data_cases, data, o.data_dir, "cloth-ball", "scalable-ccd/cloth-ball",
                "snag bench io");
  for (const std::string& input : o.inputs) data_cases.push_back(sequence_case(input, input));
  const int simulated = std::min(o.frames, 48);
  const std::vector<fs::path> obj =
      generated_cloth(o.generator, o.size, 0, simulated, scratch.path() / "obj");
  const std::string cloth = "cloth " + std::to_string(o.size);
  cases.push_back({cloth + " OBJ", true, obj});
  cases.push_back({cloth + " PLY binary", false, converted(obj, scratch.path() / "ply", true)});
  cases.push_back({cloth + " PLY ascii", false, converted(obj, scratch.path() / "ascii", false)});
  for (const BenchCase& c : data_cases) {
    bool is_obj = !c.files.empty();
    for (const fs::path& f : c.files) is_obj = is_obj && f.extension() == ".obj";
    cases.push_back({c.name, is_obj, c.files});
  }

  std::printf("snag bench io: %d threads\n", threads);
  readers_table(cases, o.passes);

  // The sequence: the simulated frames copied cyclically to --frames files.
  const fs::path sequence_dir = scratch.path() / "sequence";
  cycled_copies(obj, o.frames, sequence_dir);
  const std::vector<seq::Frame> frames = seq::resolve_sequence(sequence_dir.string());
  std::vector<std::string> backends = {"cpu"};
  std::string passed_over;
  if (resolve_auto_backend(o.device, &passed_over) == "cuda") backends.push_back("cuda");
  if (!passed_over.empty()) std::fprintf(stderr, "snag: warning: %s\n", passed_over.c_str());
  sequence_table(cloth + " OBJ", frames, backends, threads, o.device, scratch.path() / "out");
  // Each --input of two frames or more, as it is: a studio's own cache, whose pairs (a clean
  // cache has few) decide what the reports cost.
  for (const std::string& input : o.inputs) {
    const std::vector<seq::Frame> input_frames = seq::resolve_sequence(input);
    if (input_frames.size() >= 2)
      sequence_table(input, input_frames, backends, threads, o.device, scratch.path() / "out");
  }

  std::vector<int> lengths;
  for (int n : o.memory_frames)
    if (n > 0) lengths.push_back(n);
  if (!lengths.empty()) {
    const int longest = *std::max_element(lengths.begin(), lengths.end());
    const fs::path memory_dir = scratch.path() / "memory";
    cycled_copies(obj, longest, memory_dir);
    memory_table(cloth + " OBJ", (memory_dir / "frame.%04d.obj").string(), lengths, backends.back(),
                 threads, scratch.path());
  }
  return 0;
}

}  // namespace snag::cli
