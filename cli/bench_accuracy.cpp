// `snag bench accuracy`: what exactness costs. Every method runs on the same frames: snag with
// each --exact mode on each backend present, CGAL's self_intersections, and a plain
// floating-point triangle-triangle test (naive_tri_tri.h, a baseline written for this table
// only). Each is scored against the exact answer (snag --exact all, every pair confirmed by
// CGAL's own tests): false positives, false negatives, wrong kinds. The table is printed and,
// with --out, written as accuracy.csv and accuracy.md.
#include <omp.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "backend_factory.h"
#include "bench_support.h"
#include "commands.h"
#include "naive_tri_tri.h"
#include "snag/bvh/tree.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/weld.h"
#include "snag/report/csv.h"
#include "snag/report/write.h"
#include "snag/threads.h"
#include "snag/validators/cgal_reference.h"
#include "snag/validators/exact_modes.h"

namespace snag::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// One input of the table: frames sharing one topology (one frame for most files).
struct Input {
  std::string name;
  std::vector<mesh::Mesh> frames;
  int cases = 1;  ///< files folded into this row (the hard-case corpus is one row)
};

/// What a method answers for one frame.
struct Answer {
  std::vector<detect::FacePair> pairs;  ///< sorted by (a, b)
  bool has_kinds = true;
  int64_t unproven = 0;  ///< decisions outside the filter's bound (--exact off)
};

struct Method {
  std::string name;
  /// Called once per input: returns the per-frame function (state such as a built tree or a
  /// halfedge mesh lives in the closure, built once as in a sequence).
  std::function<std::function<Answer(const mesh::Mesh&)>(const mesh::Mesh& first)> prepare;
};

struct Score {
  std::string input;
  std::string method;
  int64_t triangles = 0;
  int frames = 0;
  double seconds = 0;  ///< median per frame
  int64_t pairs = 0, false_positive = 0, false_negative = 0, wrong_kind = 0, unproven = 0;
  bool has_kinds = true;
};

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

Method snag_method(const std::string& backend, detect::ExactMode mode, int threads, int device) {
  const std::string name = "snag " + backend + " --exact " + std::string(detect::to_string(mode));
  return {name, [=](const mesh::Mesh& first) {
            detect::CheckSettings settings;
            settings.exact = mode;
            settings.threads = threads;
            std::shared_ptr<detect::Checker> checker =
                validators::make_checker(make_backend(backend, threads, device), settings);
            checker->set_triangles(first.triangles, static_cast<int32_t>(first.positions.size()));
            return [checker, mode](const mesh::Mesh& m) {
              detect::FrameResult r = checker->check(m.positions);
              return Answer{std::move(r.pairs), true,
                            mode == detect::ExactMode::off ? r.uncertain_tests : 0};
            };
          }};
}

Method cgal_method() {
  return {"CGAL self_intersections", [](const mesh::Mesh& first) {
            std::shared_ptr<validators::CgalSequence> sequence;
            try {
              sequence =
                  std::make_shared<validators::CgalSequence>(first.positions, first.triangles);
            } catch (const InternalError&) {
              // Not a halfedge mesh (a soup, non-manifold edges): CGAL's rules pair by pair.
            }
            return [sequence](const mesh::Mesh& m) {
              std::vector<std::pair<int32_t, int32_t>> ids;
              if (sequence) {
                sequence->set_positions(m.positions);
                ids = sequence->self_intersections();
              } else {
                ids = validators::cgal_soup_self_intersections(m.positions, m.triangles);
              }
              Answer a;
              a.has_kinds = false;
              for (auto [x, y] : ids) a.pairs.push_back({x, y, detect::PairKind::touching});
              return a;
            };
          }};
}

/// The floating-point baseline over the candidates of snag's own tree (built per frame, so
/// that its time is the baseline's whole cost and comparable with a tool that has no refit).
Method naive_method(int threads) {
  return {"float tri-tri (no filter)", [threads](const mesh::Mesh&) {
            return [threads](const mesh::Mesh& m) {
              const auto n = static_cast<int32_t>(m.triangles.size());
              std::vector<uint8_t> flat(static_cast<size_t>(n));
              for (int32_t t = 0; t < n; ++t)
                flat[t] = naive::degenerate(m.positions, m.triangles[t]);
              bvh::Tree tree;
              tree.build({m.positions.data(), m.triangles.data(),
                          static_cast<int32_t>(m.positions.size()), n},
                         threads);
              const bvh::TreeView view = tree.view();
              std::vector<std::vector<detect::FacePair>> found(
                  static_cast<size_t>(std::max(threads, 1)));
#pragma omp parallel for num_threads(std::max(threads, 1)) schedule(dynamic, 256)
              for (int32_t position = 0; position < view.shape.leaf_count; ++position) {
                auto& out = found[static_cast<size_t>(omp_get_thread_num())];
                const int32_t t = view.triangle_at[position];
                if (flat[t]) continue;
                bvh::for_each_later_overlap(view, position, [&](int32_t x) {
                  if (flat[x]) return;
                  if (auto kind = naive::intersect(m.positions, m.triangles[t], m.triangles[x]))
                    out.push_back({std::min(t, x), std::max(t, x), *kind});
                });
              }
              Answer a;
              for (auto& part : found) a.pairs.insert(a.pairs.end(), part.begin(), part.end());
              std::sort(a.pairs.begin(), a.pairs.end(), [](const auto& x, const auto& y) {
                return x.a != y.a ? x.a < y.a : x.b < y.b;
              });
              return a;
            };
          }};
}

/// Adds the differences between `got` and the exact `truth` (both sorted by (a, b)).
void score_frame(const Answer& got, const std::vector<detect::FacePair>& truth, Score& s) {
  size_t i = 0, j = 0;
  auto less = [](const detect::FacePair& x, const detect::FacePair& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  };
  while (i < got.pairs.size() || j < truth.size()) {
    if (j == truth.size() || (i < got.pairs.size() && less(got.pairs[i], truth[j]))) {
      ++s.false_positive, ++i;
    } else if (i == got.pairs.size() || less(truth[j], got.pairs[i])) {
      ++s.false_negative, ++j;
    } else {
      if (got.has_kinds && got.pairs[i].kind != truth[j].kind) ++s.wrong_kind;
      ++i, ++j;
    }
  }
  s.pairs += static_cast<int64_t>(got.pairs.size());
  s.unproven += got.unproven;
  s.has_kinds = got.has_kinds;
}

/// The hard-case corpus: cases.csv (case,file,weld,...) when present, else every .obj file.
Input hard_corpus(const fs::path& dir) {
  Input input{"hard cases", {}, 0};
  std::vector<std::pair<fs::path, std::optional<double>>> files;
  std::ifstream list(dir / "cases.csv");
  if (list) {
    std::string line;
    std::getline(list, line);  // header
    for (int64_t line_number = 2; std::getline(list, line); ++line_number) {
      std::stringstream fields(line);
      std::string name, file, weld;
      std::getline(fields, name, ',');
      std::getline(fields, file, ',');
      std::getline(fields, weld, ',');
      if (file.empty()) continue;
      std::optional<double> tolerance;
      if (!weld.empty()) {
        double value = 0;
        const auto [end, error] = std::from_chars(weld.data(), weld.data() + weld.size(), value);
        if (error != std::errc() || end != weld.data() + weld.size() || !(value >= 0))
          throw InputError((dir / "cases.csv").string(), line_number,
                           "weld '" + weld + "' is not a number >= 0");
        tolerance = value;
      }
      files.emplace_back(dir / file, tolerance);
    }
  } else {
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".obj") files.emplace_back(entry.path(), std::nullopt);
    std::sort(files.begin(), files.end());
  }
  for (const auto& [path, weld] : files) {
    mesh::Mesh m = io::read_mesh(path);
    if (weld)
      m.triangles =
          mesh::welded_triangles(m.triangles, mesh::weld_representatives(m.positions, *weld));
    input.frames.push_back(std::move(m));
  }
  if (input.frames.empty())
    throw UsageError("--hard " + dir.string() + ": no cases in it (a cases.csv, or .obj files)");
  input.cases = static_cast<int>(input.frames.size());
  input.name += " (" + std::to_string(input.cases) + " cases)";
  return input;
}

fs::path default_hard_dir() {
  if (const char* source = std::getenv("SNAG_SOURCE_DIR")) return fs::path(source) / "samples/hard";
  return fs::path(SNAG_SOURCE_DIR_DEFAULT) / "samples/hard";
}

/// Runs every method on one input. The hard corpus's files each have their own topology, so
/// each is prepared on its own; a sequence's frames share one preparation.
std::vector<Score> run_input(const Input& input, const std::vector<Method>& methods,
                             const Method& truth_method, int warmup) {
  const bool separate = input.cases > 1;
  // The exact answer per frame.
  std::vector<std::vector<detect::FacePair>> truth;
  {
    std::function<Answer(const mesh::Mesh&)> run;
    for (size_t f = 0; f < input.frames.size(); ++f) {
      if (f == 0 || separate) run = truth_method.prepare(input.frames[f]);
      truth.push_back(run(input.frames[f]).pairs);
    }
  }
  std::vector<Score> scores;
  for (const Method& method : methods) {
    Score s;
    s.input = input.name;
    s.method = method.name;
    // A corpus row counts the triangles of all its files; a sequence's, those of a frame.
    for (size_t f = 0; f < (separate ? input.frames.size() : 1); ++f)
      s.triangles += static_cast<int64_t>(input.frames[f].triangles.size());
    s.frames = static_cast<int>(input.frames.size());
    std::vector<double> times;
    std::function<Answer(const mesh::Mesh&)> run;
    for (size_t f = 0; f < input.frames.size(); ++f) {
      const mesh::Mesh& m = input.frames[f];
      if (f == 0 || separate) run = method.prepare(m);
      for (int w = 0; w < warmup; ++w) run(m);
      const auto started = Clock::now();
      const Answer answer = run(m);
      times.push_back(seconds_since(started));
      score_frame(answer, truth[f], s);
    }
    s.seconds = median(times);
    scores.push_back(s);
  }
  return scores;
}

std::string kinds_cell(const Score& s) {
  return s.has_kinds ? std::to_string(s.wrong_kind) : "n/a";
}

void write_tables(const std::vector<Score>& scores, const fs::path& dir,
                  const std::string& header) {
  std::ostringstream csv;
  csv << "input,triangles,frames,method,ms_per_frame,pairs,false_positives,false_negatives,"
         "wrong_kinds,unproven_decisions\n";
  for (const Score& s : scores)
    csv << report::csv_field(s.input) << ',' << s.triangles << ',' << s.frames << ','
        << report::csv_field(s.method) << ',' << s.seconds * 1e3 << ',' << s.pairs << ','
        << s.false_positive << ',' << s.false_negative << ',' << kinds_cell(s) << ',' << s.unproven
        << '\n';
  std::ostringstream md;
  md << header << "\n\n| input | triangles | method | ms/frame | pairs | false + | false - "
     << "| wrong kind | unproven |\n|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
  char ms[32];
  for (const Score& s : scores) {
    std::snprintf(ms, sizeof ms, "%.3f", s.seconds * 1e3);
    md << "| " << s.input << " | " << s.triangles << " | " << s.method << " | " << ms << " | "
       << s.pairs << " | " << s.false_positive << " | " << s.false_negative << " | "
       << kinds_cell(s) << " | " << s.unproven << " |\n";
  }
  const std::string csv_text = csv.str(), md_text = md.str();
  report::write_files_atomically(dir,
                                 {{"accuracy.csv", [&](std::ostream& out) { out << csv_text; }},
                                  {"accuracy.md", [&](std::ostream& out) { out << md_text; }}});
}

}  // namespace

CLI::App* add_bench_accuracy_command(CLI::App& bench, BenchAccuracyOptions& o) {
  CLI::App* cmd = bench.add_subcommand(
      "accuracy",
      "Time and score each --exact mode, CGAL and a plain floating-point test on the same frames "
      "against the exact answer");
  add_case_options(cmd, {&o.sizes, &o.data_dir, &o.inputs, &o.generator, &o.threads},
                   "its files are inputs", "score");
  cmd->add_option("--frames", o.frames, "Frames per generated cloth")
      ->type_name("N")
      ->check(kPositiveCount)
      ->capture_default_str();
  cmd->add_option("--warmup", o.warmup, "Untimed runs of each frame before the timed one")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  cmd->add_option(
         "--hard", o.hard_dir,
         "The hard-case corpus (default: samples/hard of $SNAG_SOURCE_DIR, else of the source tree "
         "known at build time)")
      ->type_name("DIR");
  cmd->add_option("--device", o.device, "CUDA device, numbered from 0")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  cmd->add_option("-o,--out", o.out_dir, "Write accuracy.csv and accuracy.md into DIR")
      ->type_name("DIR");
  return cmd;
}

int run_bench_accuracy(const BenchAccuracyOptions& o) {
  const int threads = thread_count(o.threads);
  const char* command = "snag bench accuracy";
  std::optional<report::OutputDirectory> output_directory;
  if (!o.out_dir.empty()) output_directory.emplace(o.out_dir);

  std::vector<Input> inputs;
  const fs::path hard = o.hard_dir.empty() ? default_hard_dir() : fs::path(o.hard_dir);
  if (fs::is_directory(hard))
    inputs.push_back(hard_corpus(hard));
  else if (!o.hard_dir.empty())
    throw UsageError("--hard " + o.hard_dir + ": not a directory");
  else
    std::cerr << command << ": no hard-case corpus at " << hard.string() << "; left out\n";

  auto add_case = [&](const BenchCase& c) {
    Input input{c.name, read_case(c, command).meshes, 1};
    inputs.push_back(std::move(input));
  };
  ScratchDir scratch;
  for (int size : o.sizes) {
    if (size <= 0) continue;
    const fs::path dir = scratch.path() / ("cloth" + std::to_string(size));
    add_case({"cloth " + std::to_string(size),
              generated_cloth(o.generator, size, settle_frames, o.frames, dir)});
  }
  const fs::path data = data_folder(o.data_dir);
  // Each case of the data folder that is there (a partial copy of it is still a corpus); a
  // --data folder that holds none of them is a usage error, as a mistyped path.
  std::vector<BenchCase> data_cases;
  for (const auto& [name, folder] : std::vector<std::pair<std::string, std::string>>{
           {"cloth-ball", "scalable-ccd/cloth-ball"},
           {"cloth-funnel", "scalable-ccd/cloth-funnel"},
           {"n-body", "scalable-ccd/n-body-simulation"},
           {"armadillo-rollers", "scalable-ccd/armadillo-rollers"},
           {"rod-twist", "scalable-ccd/rod-twist"},
           {"thick-cloth", "ipc-toolkit/thick-cloth"}})
    add_data_case(data_cases, data, "", name, folder, command);
  if (!data.empty() && fs::is_directory(data / "ipc-toolkit"))
    for (const char* file :
         {"two-cubes-far.ply", "two-cubes-close.ply", "two-cubes-intersecting.ply"})
      if (fs::exists(data / "ipc-toolkit" / file))
        data_cases.push_back(
            sequence_case(std::string("ipc ") + file, (data / "ipc-toolkit" / file).string()));
  if (!o.data_dir.empty() && data_cases.empty())
    throw UsageError("--data " + o.data_dir +
                     ": none of its cases is in it (scalable-ccd/cloth-ball, cloth-funnel, "
                     "n-body-simulation, armadillo-rollers, rod-twist; ipc-toolkit/thick-cloth, "
                     "two-cubes-*.ply)");
  for (const BenchCase& c : data_cases) add_case(c);
  for (const std::string& sequence : o.inputs) add_case(sequence_case(sequence, sequence));
  if (inputs.empty()) throw UsageError("snag bench accuracy: no inputs");

  std::vector<std::string> backends = {"cpu"};
  std::string passed_over;
  const bool with_cuda = resolve_auto_backend(o.device, &passed_over) == "cuda";
  if (!passed_over.empty()) std::fprintf(stderr, "snag: warning: %s\n", passed_over.c_str());
  if (with_cuda) backends.push_back("cuda");
  std::vector<Method> methods;
  for (const std::string& backend : backends)
    for (detect::ExactMode mode :
         {detect::ExactMode::off, detect::ExactMode::uncertain, detect::ExactMode::all})
      methods.push_back(snag_method(backend, mode, threads, o.device));
  methods.push_back(cgal_method());
  methods.push_back(naive_method(threads));
  const Method truth = snag_method("cpu", detect::ExactMode::all, threads, o.device);

  std::vector<Score> scores;
  for (const Input& input : inputs) {
    std::cerr << command << ": " << input.name << "\n";
    std::vector<Score> part = run_input(input, methods, truth, o.warmup);
    scores.insert(scores.end(), part.begin(), part.end());
  }

  char header[256];
  std::snprintf(
      header, sizeof header,
      "snag bench accuracy: %d threads, %s; ms/frame is the median over the input's "
      "frames; wrong counts are summed over them, against snag --exact all (CGAL-confirmed)",
      threads, with_cuda ? "CPU and CUDA" : "CPU only (no usable CUDA device)");
  // The input column as wide as its longest name (a file given with --input can be long).
  int input_width = 28;
  for (const Score& s : scores)
    input_width = std::max(input_width, static_cast<int>(s.input.size()));
  std::printf("%s\n\n%-*s %9s %-28s %10s %8s %8s %8s %6s %9s\n", header, input_width, "input",
              "triangles", "method", "ms/frame", "pairs", "false+", "false-", "kind", "unproven");
  for (const Score& s : scores)
    std::printf("%-*s %9lld %-28s %10.3f %8lld %8lld %8lld %6s %9lld\n", input_width,
                s.input.c_str(), static_cast<long long>(s.triangles), s.method.c_str(),
                s.seconds * 1e3, static_cast<long long>(s.pairs),
                static_cast<long long>(s.false_positive), static_cast<long long>(s.false_negative),
                kinds_cell(s).c_str(), static_cast<long long>(s.unproven));
  if (output_directory) {
    write_tables(scores, o.out_dir, header);
    output_directory->keep();
  }
  return 0;
}

}  // namespace snag::cli
