// `snag check SEQUENCE`: every frame of a sequence checked for self-intersections, a summary on
// standard output and, with --out, the reports.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "backend_factory.h"
#include "check_sequence.h"
#include "commands.h"
#include "progress.h"
#include "snag/detect/checker.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/report/baseline.h"
#include "snag/report/junit.h"
#include "snag/report/report.h"
#include "snag/report/stream.h"
#include "snag/report/write.h"
#include "snag/scene/scene.h"
#include "snag/scene/scene_frames.h"
#include "snag/seq/sequence.h"
#include "snag/threads.h"
#include "snag/validators/exact_modes.h"

namespace snag::cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// An option value that may not be empty (`--out ''` would write no report, `--frames ''`
/// select nothing, silently).
CLI::Validator non_empty(const std::string& what) {
  return CLI::Validator(
      [what](std::string& value) { return value.empty() ? "expected " + what + ", found ''" : ""; },
      "", "non-empty");
}

detect::RebuildPolicy rebuild_policy(const std::string& name) {
  if (name == "never") return detect::RebuildPolicy::never;
  if (name == "always") return detect::RebuildPolicy::always;
  return detect::RebuildPolicy::automatic;
}

/// The objects to check: a scene file, SEQUENCE's groups (--split-groups), SEQUENCE with its
/// obstacles (--obstacle), or SEQUENCE alone (one object, a single-mesh run). Throws
/// UsageError for combinations that do not make one scene.
scene::Scene scene_of(const CheckOptions& o) {
  if (!o.scene.empty()) {
    if (!o.sequence.empty() || !o.obstacles.empty() || o.split_groups)
      throw UsageError(
          "--scene describes every object: give no SEQUENCE, --obstacle or "
          "--split-groups with it");
    if (o.weld) throw UsageError("--weld: with --scene, give each object's \"weld\" in the file");
    return scene::read_scene_file(o.scene);
  }
  if (o.sequence.empty()) throw UsageError("SEQUENCE is required (or --scene FILE)");
  if (!o.obstacle_groups.empty() && !o.split_groups)
    throw UsageError("--obstacle-group needs --split-groups");
  if (o.split_groups) {
    if (!o.obstacles.empty())
      throw UsageError("--split-groups and --obstacle: use a scene file (--scene) to mix them");
    const std::vector<seq::Frame> frames = seq::resolve_sequence(o.sequence);
    const std::vector<std::string> groups = scene::face_groups(io::read_mesh(frames.front().path));
    if (groups.empty())
      throw InputError(frames.front().path.string(), 0,
                       "has no faces, so no groups for --split-groups to check");
    return scene::scene_from_groups(o.sequence, groups, o.obstacle_groups, o.weld);
  }
  return scene::scene_from_flags(o.sequence, o.obstacles, o.weld);
}

/// The scene's objects as report.json lists them (closedness is filled in by the run).
std::vector<report::ObjectInput> object_inputs(const scene::ResolvedScene& scene) {
  std::vector<report::ObjectInput> objects;
  for (const scene::ResolvedObject& object : scene.objects) {
    report::ObjectInput input;
    input.name = object.spec.name;
    input.role = object.spec.role == scene::Role::cloth ? "cloth" : "obstacle";
    input.sequence = object.spec.sequence;
    input.group = object.spec.group;
    input.still = object.still;
    input.weld = object.spec.weld;
    objects.push_back(std::move(input));
  }
  return objects;
}

/// Runs of frame numbers for a warning: "2, 5-6", and ", ..." when `more` were left out.
std::string joined_runs(const std::vector<std::string>& runs, bool more) {
  std::string joined;
  for (const std::string& run : runs) (joined += joined.empty() ? "" : ", ") += run;
  if (more) joined += ", ...";
  return joined;
}

/// Frames in which every triangle of an object has zero area: a cache frame written with its
/// vertices zeroed, or a simulation collapsed to a point. Its faces pair with nothing, so the
/// frame checks clean and a gate would pass it in silence. The objects of the first kNamed such
/// frames are named in a warning as they are checked, the other frames counted in one at the end.
class CollapsedFrames {
 public:
  static constexpr int64_t kNamed = 3;
  using Warn = std::function<void(const std::string&)>;

  void note(const report::FrameRecord& r, const Warn& warn) {
    if (r.degenerate.empty()) return;
    // A single mesh is one object; a scene's degenerate faces say which object they are in.
    std::vector<int64_t> degenerate(std::max<size_t>(r.objects.size(), 1), 0);
    for (const report::Face& f : r.degenerate)
      if (static_cast<size_t>(f.object) < degenerate.size()) ++degenerate[f.object];
    bool counted = false;
    for (size_t o = 0; o < degenerate.size(); ++o) {
      const int64_t triangles = r.objects.empty() ? r.triangles : r.objects[o].triangles;
      if (triangles == 0 || degenerate[o] < triangles) continue;
      if (!counted) ++frames_;
      counted = true;
      if (frames_ > kNamed) return;
      const std::string& file = r.objects.empty() ? r.file : r.objects[o].file;
      warn("frame " + std::to_string(r.frame) + " (" + file + "): all " +
           std::to_string(triangles) +
           " triangles have zero area (vertices zeroed or collapsed?); they pair with nothing");
    }
  }
  void finish(const Warn& warn) const {
    const int64_t more = frames_ - kNamed;
    if (more > 0)
      warn(std::to_string(more) + (more == 1 ? " more frame has" : " more frames have") +
           " an object of only zero-area triangles");
  }

 private:
  int64_t frames_ = 0;
};

/// A checked frame's progress note; with a baseline, how many of its pairs the baseline accepts.
std::string frame_note(const report::FrameRecord& r, bool baseline) {
  std::string note = "frame " + std::to_string(r.frame) + ": ";
  if (r.pairs.empty()) {
    note += "clean";
  } else {
    note += std::to_string(r.crossing_count()) + " crossing, " +
            std::to_string(r.touching_count()) + " touching";
    if (baseline) note += ", " + std::to_string(r.accepted_count()) + " accepted";
  }
  if (!r.degenerate.empty()) note += ", " + std::to_string(r.degenerate.size()) + " degenerate";
  if (r.topology_changed) note += " (topology changed)";
  return note;
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string plural(int64_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

/// What the summary prints besides the frames' counts: known only at the end of the run.
struct RunTotals {
  int builds = 0;
  int rebuilds = 0;
  double wall_seconds = 0;
};

/// A scene run's objects, one line: "dress (cloth), body (obstacle, still, closed)"; the first
/// kListed of them, then how many more (--split-groups on a file of hundreds of groups made this
/// one line of tens of kilobytes). report.json, when written, lists them all.
std::string objects_line(const std::vector<report::ObjectInput>& objects, bool report_written) {
  constexpr size_t kListed = 12;
  std::string line;
  for (size_t i = 0; i < objects.size(); ++i) {
    const report::ObjectInput& o = objects[i];
    if (i == kListed) {
      line += ", and " + std::to_string(objects.size() - kListed) + " more" +
              (report_written ? " (report.json lists them)" : "");
      break;
    }
    if (!line.empty()) line += ", ";
    line += o.name + " (" + o.role;
    if (o.still) line += ", still";
    if (!o.closed.empty()) line += o.closed == "closed" ? ", closed" : ", not closed";
    line += ")";
  }
  return line;
}

/// The summary's lines about a run's baseline: what it listed and what matched, the pairs it
/// accepted, the new ones, and where the run first failed.
void print_baseline_summary(std::ostream& out, const report::Summary& s,
                            const report::BaselineUse& use, const std::string& file) {
  constexpr size_t kLinesNamed = 5;
  out << "baseline             " << file << ": " << use.entries
      << (use.entries == 1 ? " entry" : " entries");
  if (use.left_out > 0) out << " (" << use.left_out << " rows marked accepted 0 left out)";
  out << ", " << use.checked << " for the frames checked, " << use.unmatched << " matched no pair";
  if (use.unmatched > 0) {
    out << " (line";
    out << (use.unmatched == 1 ? " " : "s ");
    for (size_t i = 0; i < std::min(use.unmatched_lines.size(), kLinesNamed); ++i)
      out << (i ? ", " : "") << use.unmatched_lines[i];
    if (use.unmatched_lines.size() > kLinesNamed) out << ", ...";
    out << ")";
  }
  out << "\n";
  out << "accepted pairs       " << s.accepted << " (" << s.accepted_crossing << " crossing, "
      << s.accepted - s.accepted_crossing << " touching)\n";
  const int64_t new_pairs = s.pairs - s.accepted;
  const int64_t new_crossing = s.crossing - s.accepted_crossing;
  out << "new pairs            " << new_pairs;
  if (new_pairs > 0)
    out << " (" << new_crossing << " crossing, " << new_pairs - new_crossing << " touching) in "
        << plural(s.frames_with_new_pairs, "frame") << ", the first in frame "
        << *s.first_new_frame;
  out << "\n";
  if (s.first_failing_frame) out << "first failing frame  " << *s.first_failing_frame << "\n";
}

/// `baseline_file`: --baseline as given, empty without one (inputs.baseline is then not read).
void print_summary(std::ostream& out, const report::Summary& s, const RunTotals& totals,
                   const std::string& rebuild_policy, const std::string& out_dir,
                   const report::Inputs& inputs, const std::string& baseline_file) {
  if (inputs.scene())
    out << "objects              " << objects_line(inputs.objects, !out_dir.empty()) << "\n";
  out << "frames checked       " << s.frames_checked << "\n";
  out << "frames with crossing " << s.frames_with_crossings << "\n";
  out << "worst frame          ";
  if (s.worst) {
    out << s.worst->frame << " (" << s.worst->file << "): " << s.worst->crossing << " crossing, "
        << s.worst->touching() << " touching\n";
  } else {
    out << "none\n";
  }
  out << "pairs                " << s.pairs << " (" << s.crossing << " crossing, " << s.touching
      << " touching)\n";
  if (!baseline_file.empty()) print_baseline_summary(out, s, inputs.baseline, baseline_file);
  if (s.degenerate > 0) out << "degenerate faces     " << s.degenerate << "\n";
  if (inputs.scene()) {
    out << "reused pairs         " << s.reused_pairs << " (checks whose objects did not move)\n";
    out << "deepest penetration  " << fixed(s.max_depth, 6) << "\n";
  }
  const double per_frame = s.frames_checked > 0 ? s.check_seconds / s.frames_checked : 0.0;
  out << "time                 " << fixed(s.check_seconds, 3) << " s checking ("
      << fixed(per_frame * 1e3, 2) << " ms per frame), " << fixed(s.read_seconds, 3)
      << " s reading (ahead, on other threads), " << fixed(totals.wall_seconds, 3) << " s in all\n";
  out << "tree                 " << plural(totals.builds, "build") << ", "
      << plural(totals.rebuilds, "rebuild") << " (--rebuild " << rebuild_policy << "), "
      << plural(s.topology_changes, "topology change") << "\n";
  if (!out_dir.empty())
    out << "reports              " << (std::filesystem::path(out_dir) / "").string()
        << "{pairs.csv,frames.csv,report.json}\n";
}

/// The --junit file, refused before any frame (WriteError) where it could not be the run's new
/// file, or would replace something that is not a report of snag's: no file name ("dir/",
/// "x/.."), "-", something other than a regular file in its place (a directory, a device, a
/// link, which the rename would replace rather than write through), or a file the run reads or
/// writes (the baseline, the scene file, a frame, a report of --out).
std::filesystem::path junit_path_of(const CheckOptions& o, const scene::ResolvedScene& resolved) {
  namespace fs = std::filesystem;
  const fs::path path(o.junit);
  const fs::path name = path.filename();
  if (o.junit == "-" || name.empty() || name == "." || name == "..")
    throw report::WriteError(path, "not a file name; --junit names the file to write");
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw report::WriteError(path, std::string(fs::is_directory(status) ? "a directory"
                                               : fs::is_symlink(status) ? "a symbolic link"
                                                                        : "not a regular file") +
                                       "; --junit writes a new file in its place");
  // Compared as the filesystem resolves them ("seq/../seq/f.0002.obj" is a frame), or by their
  // spelling where a path cannot be resolved (a directory that cannot be read).
  const fs::path target = fs::weakly_canonical(path, error);
  const bool resolved_target = !error;
  const auto same = [&](const fs::path& other) {
    std::error_code other_error;
    const fs::path resolved_other = fs::weakly_canonical(other, other_error);
    if (resolved_target && !other_error) return resolved_other == target;
    return other.lexically_normal() == path.lexically_normal();
  };
  const auto refuse = [&](const std::string& what) {
    throw report::WriteError(path, "is " + what + "; --junit would replace it");
  };
  if (!o.baseline.empty() && same(o.baseline)) refuse("the --baseline");
  if (!o.scene.empty() && same(o.scene)) refuse("the scene file");
  if (!o.out_dir.empty())
    for (const char* report : {"pairs.csv", "frames.csv", "report.json"})
      if (same(fs::path(o.out_dir) / report)) refuse("a report of --out");
  for (const scene::ResolvedObject& object : resolved.objects)
    for (const seq::Frame& frame : object.frames)
      if (same(frame.path)) refuse("a frame of " + object.spec.sequence);
  return path;
}

/// A sequence whose frames are files of several kinds ('dress.*' matching dress.0003.obj.bak
/// beside the .obj frames, read through assimp): each is a frame, which is rarely what was
/// meant; said once, with the count of each kind.
void warn_of_mixed_kinds(const scene::ResolvedScene& resolved,
                         const std::function<void(const std::string&)>& warn) {
  for (const scene::ResolvedObject& object : resolved.objects) {
    std::map<std::string, int> kinds;
    for (const seq::Frame& f : object.frames) {
      const std::string kind = io::lowercase_extension(f.path);
      ++kinds[kind.empty() ? "(none)" : kind];
    }
    if (kinds.size() < 2) continue;
    std::string counts;
    for (const auto& [kind, count] : kinds)
      counts += (counts.empty() ? "" : ", ") + kind + ": " + std::to_string(count);
    warn(object.spec.sequence + " matched files of several kinds (" + counts +
         "); each is read as a frame");
  }
}

}  // namespace

CLI::App* add_check_command(CLI::App& app, CheckOptions& o) {
  CLI::App* cmd = app.add_subcommand(
      "check", "Check every frame of SEQUENCE for self-intersections and report them");
  cmd->add_option("SEQUENCE", o.sequence,
                  "One OBJ/PLY (or other mesh) file, a directory of them, a pattern with %04d, "
                  "####, @ or $F4, or a quoted glob (the cloth; not with --scene)");
  cmd->add_option("--obstacle", o.obstacles,
                  "A body or prop SEQUENCE checked against the cloth (one file: still); "
                  "repeatable. Its own self-intersections are not checked")
      ->type_name("SEQUENCE")
      ->check(not_an_option("a sequence"))
      ->expected(1)  // one value a flag, repeated: `--obstacle body.obj dress.%04d.obj` works
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("--scene", o.scene,
                  "A scene file (JSON): objects, their roles, checks, weld and ignore rules")
      ->type_name("FILE")
      ->check(not_an_option("a scene file"));
  cmd->add_flag("--split-groups", o.split_groups,
                "Each OBJ o/g group of SEQUENCE is an object of its own, checked against itself "
                "and every other group");
  cmd->add_option("--obstacle-group", o.obstacle_groups,
                  "With --split-groups: this group is an obstacle (not checked against itself "
                  "or other obstacles); repeatable")
      ->type_name("NAME")
      ->expected(1)
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("-o,--out", o.out_dir,
                  "Write pairs.csv, frames.csv and report.json into DIR (created if missing)")
      ->type_name("DIR")
      ->check(non_empty("a directory"))
      ->check(not_an_option("a directory"));
  cmd->add_option("--frames", o.frames, "Check only these frames: 1-240, 1-240x5, 1-10,20-30")
      ->type_name("SEL")
      ->check(non_empty("a frame selection"));
  cmd->add_option("--weld", o.weld,
                  "Vertices at most TOL apart count as one for adjacency (reports keep the "
                  "file's ids)")
      ->type_name("TOL")
      ->check(kNonNegative);
  cmd->add_option("--rebuild", o.rebuild,
                  "When to rebuild the tree instead of refitting it: never, auto (when its "
                  "quality degrades past --rebuild-threshold), always")
      ->type_name("POLICY")
      ->check(CLI::IsMember({"never", "auto", "always"}))
      ->capture_default_str();
  cmd->add_option("--rebuild-threshold", o.rebuild_threshold,
                  "With --rebuild auto: rebuild when the refit tree's quality exceeds this "
                  "factor times its quality after the last build")
      ->type_name("FACTOR")
      ->check(number_above(1, false, "FLOAT >= 1"))
      ->capture_default_str();
  cmd->add_option(
         "--backend", o.backend,
         "Detection backend: auto (the GPU when snag has CUDA and a device that can run it is "
         "present, else the CPU), cpu, or cuda (exit status 4 when not built, no device, or "
         "one that cannot run it)")
      ->type_name("NAME")
      ->check(CLI::IsMember(
          std::vector<std::string>(std::begin(backend_names), std::end(backend_names))))
      ->capture_default_str();
  cmd->add_option("--device", o.device, "CUDA device for the cuda backend, numbered from 0")
      ->type_name("N")
      ->check(kCount)
      ->capture_default_str();
  cmd->add_option("-j,--threads", o.threads,
                  "Threads of the run (from 8 on the CPU, its readers' too); 0 uses every core, "
                  "or OMP_NUM_THREADS when set")
      ->type_name("N")
      ->check(kThreadCount)
      ->capture_default_str();
  cmd->add_option("--fail-on", o.fail_on,
                  "Exit with status 1 when a frame has: crossing pairs, any pair, or none (never)")
      ->type_name("WHAT")
      ->check(CLI::IsMember({"crossing", "any", "none"}))
      ->capture_default_str();
  cmd->add_option("--baseline", o.baseline,
                  "Pairs accepted earlier: a pairs.csv (frame, face_a, face_b, optional kind; "
                  "object_a, object_b with several objects), rows cut as wanted, frame * for "
                  "every frame, rows marked accepted 0 left out. Reported, they do not fail the "
                  "run")
      ->type_name("FILE")
      ->check(non_empty("a baseline file"))
      ->check(not_an_option("a baseline file"));
  cmd->add_option("--junit", o.junit,
                  "Also write a JUnit XML report to FILE for a CI server to show: a test case "
                  "per frame, failing as --fail-on says")
      ->type_name("FILE")
      ->check(non_empty("a file"))
      ->check(not_an_option("a file"));
  cmd->add_option("--exact", o.exact,
                  "How signs are decided: off (the double filter decides all, even where its "
                  "error bound cannot; fast, may be wrong on degenerate input), uncertain (what "
                  "the filter cannot certify goes to CGAL's exact predicates), all (everything "
                  "exactly, every pair confirmed by CGAL's own triangle tests)")
      ->type_name("MODE")
      ->check(CLI::IsMember({"off", "uncertain", "all"}))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o.quiet, "No progress and no warnings on standard error");
  return cmd;
}

int run_check(const CheckOptions& o) {
  const auto started = Clock::now();
  const auto fail_on = report::parse_fail_on(o.fail_on);
  if (!fail_on)
    throw UsageError("--fail-on: expected crossing, any or none, got '" + o.fail_on + "'");
  // The command line's validators (commands.h) reject these already, NaN included; checked
  // again, NaN-proof, for callers that fill CheckOptions themselves.
  if (o.weld && !(*o.weld >= 0)) throw UsageError("--weld: TOL must be a number >= 0");
  if (!(o.rebuild_threshold >= 1))
    throw UsageError("--rebuild-threshold: FACTOR must be a number >= 1");
  const auto exact = detect::parse_exact_mode(o.exact);
  if (!exact) throw UsageError("--exact: expected off, uncertain or all, got '" + o.exact + "'");

  const scene::Scene scene = scene_of(o);
  const scene::ResolvedScene resolved = scene::resolve_scene(scene, o.frames);
  Progress progress(static_cast<int64_t>(resolved.frames.size()), o.quiet);
  const auto warn = [&](const std::string& warning) {
    if (!o.quiet) progress.message("snag: warning: " + warning);
  };
  warn_of_mixed_kinds(resolved, warn);
  if (!resolved.absent_frames.empty()) {
    // Not an error: a selection may reach past a cache on purpose. But a gate should not pass
    // frames it never saw in silence.
    warn("--frames " + o.frames + " names frames the sequence does not have (" +
         joined_runs(resolved.absent_frames, resolved.more_absent_frames) +
         "); they are not checked");
  }
  if (!resolved.gaps.runs.empty()) {
    // A frame lost from a cache (a failed write, a partial copy) would otherwise pass unseen.
    const seq::FrameGaps& gaps = resolved.gaps;
    const std::string grid = gaps.step == 1 ? "" : ", counting by " + std::to_string(gaps.step);
    warn("the sequence skips frame numbers " + joined_runs(gaps.runs, gaps.more) +
         " (between its first frame, " + std::to_string(gaps.first) + ", and its last, " +
         std::to_string(gaps.last) + grid + "); only the frames present are checked");
  }
  const bool scene_run = !o.scene.empty() || o.split_groups || !o.obstacles.empty();
  // The output directory is checked before the first frame, so an unusable --out fails at
  // once rather than after an hour of checking.
  std::optional<report::OutputDirectory> output_directory;
  if (!o.out_dir.empty()) output_directory.emplace(o.out_dir);
  // So is a --junit that cannot be written, or would replace what is not a report.
  std::optional<report::OutputDirectory> junit_directory;
  std::filesystem::path junit_path, junit_dir;
  if (!o.junit.empty()) {
    junit_path = junit_path_of(o, resolved);
    junit_dir = junit_path.parent_path().empty() ? "." : junit_path.parent_path();
    junit_directory.emplace(junit_dir);
  }
  // So is a baseline that cannot be read, or that names objects this run does not have.
  report::Inputs inputs;
  inputs.sequence = o.scene.empty() ? o.sequence : o.scene;
  if (scene_run) inputs.objects = object_inputs(resolved);
  std::optional<report::Baseline> baseline;
  if (!o.baseline.empty()) baseline = report::Baseline::read(o.baseline, inputs.objects);

  // The run's threads are the checker's and its readers' (checker_threads_for).
  const int threads = thread_count(o.threads);
  std::string backend_note;
  const std::string_view backend_choice =
      o.backend == "auto" ? resolve_auto_backend(o.device, &backend_note) : o.backend;
  if (!backend_note.empty()) warn(backend_note);
  const bool on_gpu = backend_choice == "cuda";
  const int checker_threads = checker_threads_for(threads, on_gpu);
  auto backend = make_backend(backend_choice, checker_threads, o.device);
  const std::string backend_name(backend->name());
  detect::CheckSettings settings;
  settings.threads = checker_threads;
  settings.rebuild = rebuild_policy(o.rebuild);
  settings.rebuild_threshold = o.rebuild_threshold;
  settings.exact = *exact;
  const std::unique_ptr<detect::Checker> checker =
      validators::make_checker(std::move(backend), settings);

  report::Settings report_settings;
  report_settings.backend = backend_name;
  report_settings.backend_requested = o.backend;
  report_settings.threads = threads;
  report_settings.exact = std::string(detect::to_string(*exact));
  report_settings.exact_predicates = *exact == detect::ExactMode::off ? "rounded" : "cgal";
  report_settings.weld = o.weld;
  report_settings.rebuild = o.rebuild;
  report_settings.rebuild_threshold = o.rebuild_threshold;
  report_settings.fail_on = *fail_on;
  if (!o.frames.empty()) report_settings.frames = o.frames;
  if (baseline) report_settings.baseline = o.baseline;
  // Each frame's record is written to the reports' temporaries as soon as it is checked and
  // dropped: a run holds one frame's pairs, never the sequence's. The reports appear only when
  // finish() renames them into place; an exception before that (a bad frame 7) unwinds the
  // stream, which removes its temporaries.
  std::optional<std::filesystem::path> report_dir;
  if (!o.out_dir.empty()) report_dir = o.out_dir;
  // Frames are formatted side by side when they come faster than one thread formats them (a
  // GPU's checks of many pairs); the formatters idle otherwise.
  report::ReportStream reports(report_dir, SNAG_VERSION, std::move(report_settings), inputs.objects,
                               threads);
  std::optional<report::JunitReport> junit;
  if (!o.junit.empty()) junit.emplace(inputs.sequence, *fail_on, inputs.objects);

  SequenceSettings sequence;
  sequence.weld = o.weld;
  sequence.threads = threads;
  sequence.gpu = backend_name == "cuda";
  CollapsedFrames collapsed;
  bool topology_warned = false;
  check_scene(
      resolved, *checker, sequence, scene_run, inputs,
      [&](report::FrameRecord&& record) {
        if (baseline) {
          // Baseline rows name faces by id, and ids mean other faces after the face list
          // changed: said once, at the first such frame (before its marks, which may fail).
          if (record.topology_changed && !topology_warned) {
            topology_warned = true;
            warn("frame " + std::to_string(record.frame) +
                 " has another face list than the frame before: the --baseline's face ids may "
                 "name other faces from there on");
          }
          baseline->mark(record);
        }
        collapsed.note(record, warn);
        progress.update(reports.summary().frames_checked + 1,
                        frame_note(record, baseline.has_value()));
        if (junit) junit->add(record);
        reports.add(std::move(record));
      },
      warn);
  collapsed.finish(warn);
  progress.finish();

  RunTotals totals;
  totals.builds = checker->build_count();
  totals.rebuilds = checker->rebuild_count();
  totals.wall_seconds = seconds_since(started);
  if (baseline) inputs.baseline = baseline->use();
  // Only now, with every frame read, checked and written, do the report files appear: the
  // JUnit file first (written whole under a temporary name beside it and renamed into place),
  // so that a run that cannot write it leaves no new report at all; then --out's.
  if (junit) {
    report::write_files_atomically(junit_dir, {{junit_path.filename().string(),
                                                [&](std::ostream& out) { junit->write(out); }}});
    junit_directory->keep();
  }
  const report::Summary summary =
      reports.finish(inputs, totals.builds, totals.rebuilds, totals.wall_seconds);
  if (output_directory) output_directory->keep();

  print_summary(std::cout, summary, totals, o.rebuild, o.out_dir, inputs, o.baseline);
  std::cout.flush();
  // A summary that did not reach standard output makes the run's status 3 (cli/main.cpp), not
  // the 1 this line would announce.
  if (summary.failed && !o.quiet && std::cout)
    std::cerr << "snag: "
              << (baseline ? "new intersections found, not in the baseline" : "intersections found")
              << " (--fail-on " << o.fail_on << "): exit status 1\n";
  return summary.failed ? 1 : 0;
}

}  // namespace snag::cli
