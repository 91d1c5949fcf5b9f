// The `snag` executable end to end: hand-built sequences with exact expected reports, exit
// statuses 0 to 3, no report left by a failed run, and --help against the man page.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/run_snag.h"
#include "test_paths.h"

namespace snag::test {
namespace {

namespace fs = std::filesystem;

/// A quad (polygon 0: triangles (0,1,2) and (0,2,3) in the z = 0 plane) and a triangle B
/// (polygon 1) standing across the quad's second triangle: exactly one crossing pair. The quad's
/// two triangles share an edge and lie flat, side by side: not a pair.
constexpr const char* quad_vertices = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\n";
constexpr const char* b_crossing = "v 1 3 -1\nv 1 3 1\nv 0.6 3.3 0\n";
constexpr const char* b_away = "v 11 3 -1\nv 11 3 1\nv 10.6 3.3 0\n";

/// Frame 1: quad then B. Frame 2: the face list reordered (B first): a topology change, the
/// pair is now (0, 2). Frame 3: same faces as frame 2, B moved away: clean.
fs::path write_hand_built_sequence(const fs::path& dir) {
  fs::create_directories(dir);
  write_text(dir / "f.0001.obj",
             std::string("# frame 1\n") + quad_vertices + b_crossing + "f 1 2 3 4\nf 5 6 7\n");
  write_text(dir / "f.0002.obj", std::string(quad_vertices) + b_crossing + "f 5 6 7\nf 1 2 3 4\n");
  write_text(dir / "f.0003.obj", std::string(quad_vertices) + b_away + "f 5 6 7\nf 1 2 3 4\n");
  return dir;
}

std::string without_column(const std::string& csv, const std::string& column) {
  const auto rows = parse_csv(csv);
  if (rows.empty()) return {};
  const auto it = std::find(rows[0].begin(), rows[0].end(), column);
  const size_t skip =
      it == rows[0].end() ? rows[0].size() : static_cast<size_t>(it - rows[0].begin());
  std::string out;
  for (const auto& row : rows) {
    bool first = true;
    for (size_t i = 0; i < row.size(); ++i) {
      if (i == skip) continue;
      out += (first ? "" : ",") + row[i];
      first = false;
    }
    out += "\n";
  }
  return out;
}

std::string context(const RunResult& r) {
  return "stdout:\n" + r.out + "\nstderr:\n" + r.err;
}

TEST(CliCheck, HandBuiltSequenceReports) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult r = run_snag({"check", "seq", "--out", "out", "--rebuild", "never"}, tmp.path());
  ASSERT_EQ(r.status, 1) << context(r);

  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"),
            "frame,face_a,face_b,kind,poly_a,poly_b\n"
            "1,1,2,crossing,0,1\n"
            "2,0,2,crossing,0,1\n");
  EXPECT_EQ(without_column(read_text(tmp.path() / "out" / "frames.csv"), "seconds"),
            "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,rebuilt,"
            "topology_changed\n"
            "1,seq/f.0001.obj,3,1,1,0,0,0,1,0\n"
            "2,seq/f.0002.obj,3,1,1,0,0,0,1,1\n"
            "3,seq/f.0003.obj,3,0,0,0,0,0,0,0\n");

  const auto j = nlohmann::json::parse(read_text(tmp.path() / "out" / "report.json"));
  EXPECT_EQ(j.at("schema"), "snag-report/2");
  // The default backend, auto, is the GPU where snag has CUDA and a device is present.
  const std::string backend = j.at("settings").at("backend");
  EXPECT_TRUE(backend == "cpu" || backend == "cuda") << backend;
  EXPECT_EQ(j.at("settings").at("backend_requested"), "auto");
  EXPECT_EQ(j.at("settings").at("rebuild"), "never");
  EXPECT_EQ(j.at("settings").at("fail_on"), "crossing");
  EXPECT_TRUE(j.at("settings").at("weld").is_null());
  EXPECT_EQ(j.at("inputs").at("sequence"), "seq");
  EXPECT_EQ(j.at("inputs").at("ids"), "file");
  EXPECT_EQ(j.at("inputs").at("files"),
            (nlohmann::json{"seq/f.0001.obj", "seq/f.0002.obj", "seq/f.0003.obj"}));
  ASSERT_EQ(j.at("frames").size(), 3u);
  EXPECT_EQ(j.at("frames").at(0).at("pairs"),
            (nlohmann::json::array(
                {{{"a", 1}, {"b", 2}, {"kind", "crossing"}, {"poly_a", 0}, {"poly_b", 1}}})));
  EXPECT_EQ(j.at("frames").at(0).at("polygons"), 2);
  EXPECT_EQ(j.at("frames").at(1).at("topology_changed"), true);
  EXPECT_EQ(j.at("frames").at(2).at("topology_changed"), false);
  const auto& s = j.at("summary");
  EXPECT_EQ(s.at("frames_checked"), 3);
  EXPECT_EQ(s.at("frames_with_crossings"), 2);
  EXPECT_EQ(s.at("worst_frame").at("frame"), 1);
  EXPECT_EQ(s.at("pairs"), 2);
  EXPECT_EQ(s.at("topology_changes"), 1);
  EXPECT_EQ(s.at("builds"), 2);
  EXPECT_EQ(s.at("rebuilds"), 0);
  EXPECT_EQ(s.at("failed"), true);

  // The human summary ends standard output.
  EXPECT_NE(r.out.find("frames checked       3\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frames with crossing 2\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worst frame          1 (seq/f.0001.obj): 1 crossing, 0 touching\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("1 topology change\n"), std::string::npos) << r.out;
}

TEST(CliCheck, CleanSelectionExitsZero) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult r = run_snag({"check", "seq", "--frames", "3", "--out", "out"}, tmp.path());
  EXPECT_EQ(r.status, 0) << context(r);
  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"),
            "frame,face_a,face_b,kind,poly_a,poly_b\n");
  EXPECT_NE(r.out.find("frames checked       1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worst frame          none\n"), std::string::npos) << r.out;
}

TEST(CliCheck, FailOnDecidesTheStatus) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  EXPECT_EQ(run_snag({"check", "seq", "--fail-on", "none", "-q"}, tmp.path()).status, 0);
  EXPECT_EQ(run_snag({"check", "seq", "--fail-on", "any", "-q"}, tmp.path()).status, 1);
  const RunResult quiet = run_snag({"check", "seq", "--quiet"}, tmp.path());
  EXPECT_EQ(quiet.status, 1);
  EXPECT_EQ(quiet.err, "") << "--quiet prints nothing on standard error";
}

TEST(CliCheck, ProgressIsOneLinePerFrameWhenNotATerminal) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult r = run_snag({"check", "seq"}, tmp.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no bar when standard error is a file";
  EXPECT_NE(r.err.find("[3/3] frame 3: clean"), std::string::npos) << r.err;
}

// On a terminal the progress is one bar redrawn in place ("\r" and erase to the line's end); a
// line longer than the terminal would wrap and leave its first rows behind at each redraw, so
// each drawing is cut a column short of the width. The bar is erased before the summary.
TEST(CliCheck, ProgressOnATerminalIsABarCutToItsWidth) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const std::string redraw = "\r\033[K";
  for (const int columns : {40, 200}) {
    SCOPED_TRACE(std::to_string(columns) + " columns");
    const std::optional<RunResult> run =
        run_snag_in_terminal({"check", "seq"}, tmp.path(), columns);
    if (!run) GTEST_SKIP() << "no pseudo-terminal can be opened here: the bar is not tested";
    const RunResult& r = *run;
    EXPECT_EQ(r.status, 1) << r.out;
    // The drawings: what follows each redraw up to the next control character.
    std::vector<std::string> drawn;
    for (size_t at = r.out.find(redraw); at != std::string::npos; at = r.out.find(redraw, at)) {
      at += redraw.size();
      const size_t end = r.out.find_first_of("\r\n\033", at);
      drawn.push_back(r.out.substr(at, end - at));
    }
    // One per frame, then the erase, right before the summary (on standard output, the same
    // terminal).
    ASSERT_EQ(drawn.size(), 4u) << r.out;
    const std::vector<std::string> full = {
        "[##########....................] 1/3  frame 1: 1 crossing, 0 touching",
        "[####################..........] 2/3  frame 2: 1 crossing, 0 touching (topology changed)",
        "[##############################] 3/3  frame 3: clean"};
    for (size_t i = 0; i < full.size(); ++i)
      EXPECT_EQ(drawn[i], full[i].substr(0, std::min<size_t>(full[i].size(), columns - 1)));
    EXPECT_EQ(drawn[3], "frames checked       3");
  }
}

// --frames naming frames the sequence lacks (a cache with a frame missing, or cut short), or a
// sequence that skips a number: the frames there are checked, and a warning names the ones
// that are not; a broken link among the frames is an input error naming it.
TEST(CliCheck, FramesTheSequenceLacksAreNamed) {
  TempDir tmp;
  const fs::path seq = write_hand_built_sequence(tmp.path() / "seq");
  fs::rename(seq / "f.0002.obj", seq / "f.0004.obj");  // frames 1, 3 and 4
  const RunResult gap = run_snag({"check", "seq", "--frames", "1-6"}, tmp.path());
  EXPECT_EQ(gap.status, 1) << context(gap);
  EXPECT_NE(gap.err.find("--frames 1-6 names frames the sequence does not have (2, 5-6)"),
            std::string::npos)
      << gap.err;
  EXPECT_NE(gap.out.find("frames checked       3"), std::string::npos) << gap.out;
  const RunResult quiet = run_snag({"check", "seq", "--frames", "1-6", "-q"}, tmp.path());
  EXPECT_EQ(quiet.err.find("warning"), std::string::npos) << quiet.err;
  const RunResult whole = run_snag({"check", "seq", "--frames", "1-4"}, tmp.path());
  EXPECT_NE(whole.err.find("does not have (2);"), std::string::npos) << whole.err;
  // Without --frames, the numbers the sequence skips are named all the same.
  const RunResult plain = run_snag({"check", "seq"}, tmp.path());
  EXPECT_EQ(plain.status, 1) << context(plain);
  EXPECT_NE(plain.err.find("warning: the sequence skips frame numbers 2 (between its first "
                           "frame, 1, and its last, 4); only the frames present are checked"),
            std::string::npos)
      << plain.err;
  EXPECT_EQ(whole.err.find("skips"), std::string::npos) << whole.err;

  fs::create_symlink(seq / "gone.obj", seq / "f.0005.obj");
  const RunResult broken = run_snag({"check", "seq", "--out", "r"}, tmp.path());
  EXPECT_EQ(broken.status, 3) << context(broken);
  EXPECT_NE(broken.err.find("f.0005.obj: cannot open"), std::string::npos) << broken.err;
  EXPECT_FALSE(fs::exists(tmp.path() / "r" / "pairs.csv"));
}

// A glob that matches files of several kinds (a backup beside the frames) reads each as a
// frame: a warning counts the kinds.
TEST(CliCheck, GlobsMatchingSeveralKindsOfFileWarn) {
  TempDir tmp;
  const fs::path seq = write_hand_built_sequence(tmp.path() / "seq");
  fs::copy_file(seq / "f.0003.obj", seq / "f.0004.obj.bak");
  const RunResult mixed = run_snag({"check", "seq/f.*"}, tmp.path());
  EXPECT_NE(mixed.err.find("seq/f.* matched files of several kinds (.bak: 1, .obj: 3)"),
            std::string::npos)
      << context(mixed);
  const RunResult plain = run_snag({"check", "seq/f.*.obj"}, tmp.path());
  EXPECT_EQ(plain.err.find("several kinds"), std::string::npos) << plain.err;
}

// A file without triangles checks clean, with a warning that says so: alone, as an obstacle
// (whose empty tree has no pairs with the cloth) and as a cloth with an obstacle.
TEST(CliCheck, FilesWithoutTrianglesWarnAndCheckClean) {
  TempDir tmp;
  write_text(tmp.path() / "empty.obj", "");
  write_text(tmp.path() / "points.obj", "v 0 0 0\nv 1 0 0\n");
  // Two triangles crossing each other: one crossing pair.
  write_text(tmp.path() / "x.obj",
             "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 0.5 0.2 -1\nv 0.5 0.2 1\nv 0.5 1 0\nf 1 2 3\nf 4 5 6\n");
  const RunResult alone = run_snag({"check", "empty.obj", "--out", "a"}, tmp.path());
  EXPECT_EQ(alone.status, 0) << context(alone);
  EXPECT_NE(alone.err.find("empty.obj: no triangles (0 vertices)"), std::string::npos) << alone.err;
  EXPECT_EQ(read_text(tmp.path() / "a" / "pairs.csv"), "frame,face_a,face_b,kind,poly_a,poly_b\n");

  const RunResult obstacle =
      run_snag({"check", "x.obj", "--obstacle", "points.obj", "--out", "b"}, tmp.path());
  EXPECT_EQ(obstacle.status, 1) << context(obstacle);
  EXPECT_NE(obstacle.err.find("points.obj: no triangles (2 vertices)"), std::string::npos)
      << obstacle.err;
  EXPECT_EQ(read_text(tmp.path() / "b" / "pairs.csv"),
            "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n"
            "0,0,1,crossing,0,1,cloth,cloth\n");

  // --obstacle takes one value: the cloth's SEQUENCE may follow it.
  const RunResult before = run_snag(
      {"check", "--obstacle", "points.obj", "--obstacle", "empty.obj", "x.obj", "-q"}, tmp.path());
  EXPECT_EQ(before.status, 1) << context(before);
  EXPECT_NE(before.out.find("objects              cloth (cloth), points (obstacle"),
            std::string::npos)
      << before.out;

  const RunResult cloth = run_snag({"check", "empty.obj", "--obstacle", "x.obj", "-q"}, tmp.path());
  EXPECT_EQ(cloth.status, 0) << context(cloth);
  EXPECT_EQ(cloth.err, "") << "--quiet: no warning";
}

// A frame whose vertices were all zeroed (a failed cache write) has only zero-area triangles:
// it checks clean, so a warning names it (the first three, then a count of the rest).
TEST(CliCheck, FramesOfOnlyZeroAreaTrianglesAreNamed) {
  TempDir tmp;
  fs::create_directories(tmp.path() / "seq");
  const std::string faces = "f 1 2 3\nf 1 3 4\n";
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n" + faces;
  const std::string zeroed = "v 0 0 0\nv 0 0 0\nv 0 0 0\nv 0 0 0\n" + faces;
  for (int frame = 1; frame <= 8; ++frame) {
    char name[32];
    std::snprintf(name, sizeof name, "f.%04d.obj", frame);
    write_text(tmp.path() / "seq" / name, frame == 1 || frame == 8 ? square : zeroed);
  }
  const RunResult r = run_snag({"check", "seq", "--out", "r"}, tmp.path());
  EXPECT_EQ(r.status, 0) << context(r);
  for (int frame : {2, 3, 4})
    EXPECT_NE(r.err.find("frame " + std::to_string(frame) + " (seq/f.000" + std::to_string(frame) +
                         ".obj): all 2 triangles have zero area (vertices zeroed or collapsed?)"),
              std::string::npos)
        << r.err;
  EXPECT_EQ(r.err.find("frame 5 (seq"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 more frames have an object of only zero-area triangles"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("frame 1 (seq"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("frame 8 (seq"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("degenerate faces     12"), std::string::npos) << r.out;
  const RunResult quiet = run_snag({"check", "seq", "-q"}, tmp.path());
  EXPECT_EQ(quiet.err, "") << "--quiet: no warning";
  // Beside an obstacle, the zeroed object is named, not the frame as a whole.
  write_text(tmp.path() / "body.obj", "v 5 5 5\nv 6 5 5\nv 5 6 5\nf 1 2 3\n");
  const RunResult scene = run_snag({"check", "seq", "--obstacle", "body.obj"}, tmp.path());
  EXPECT_EQ(scene.status, 0) << context(scene);
  EXPECT_NE(scene.err.find("frame 2 (seq/f.0002.obj): all 2 triangles have zero area"),
            std::string::npos)
      << scene.err;
  EXPECT_EQ(scene.err.find("body.obj): all"), std::string::npos) << scene.err;
  EXPECT_NE(scene.err.find("3 more frames have"), std::string::npos) << scene.err;
}

/// 3,000 frames in `dir` (the drape sample's 12 over and over, as links): a run long enough to
/// still be going when its report temporaries have appeared.
void link_long_drape_sequence(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path drape = source_dir() / "samples" / "drape";
  for (int f = 1; f <= 3000; ++f) {
    char name[32], sample[32];
    std::snprintf(name, sizeof name, "f.%04d.obj", f);
    std::snprintf(sample, sizeof sample, "drape.%04d.obj", (f - 1) % 12 + 1);
    fs::create_symlink(drape / sample, dir / name);
  }
}

/// The report temporaries in `out` (".tmp-" in their names), each followed by a space.
std::string report_temporaries(const fs::path& out) {
  std::string names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out, ec))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos)
      names += entry.path().filename().string() + " ";
  return names;
}

/// `snag check seq --backend cpu -q --fail-on none --out OUT` started in `cwd` in a child
/// process, with the given signals' dispositions set there first.
pid_t start_long_check(const fs::path& cwd, const fs::path& out,
                       std::initializer_list<std::pair<int, sighandler_t>> dispositions) {
  const std::string executable = snag_executable().string();
  const pid_t child = ::fork();
  if (child != 0) return child;
  for (const auto& [signal_number, handler] : dispositions) ::signal(signal_number, handler);
  if (::chdir(cwd.c_str()) != 0) ::_exit(127);
  ::execl(executable.c_str(), executable.c_str(), "check", "seq", "--backend", "cpu", "-q",
          "--fail-on", "none", "--out", out.c_str(), static_cast<char*>(nullptr));
  ::_exit(127);
}

/// How a wait for a run's report temporaries ended: `seen` them (they come and go, the output
/// probe's among them: seen once is enough), or the run `ended` first (its wait `status`); after
/// 30 s, neither.
struct TemporariesWait {
  bool seen = false;
  pid_t ended = 0;
  int status = 0;
};
TemporariesWait wait_for_temporaries(pid_t child, const fs::path& out) {
  TemporariesWait w;
  for (int wait = 0; wait < 30000 && !w.seen && w.ended == 0; ++wait) {
    w.seen = !report_temporaries(out).empty();
    if (!w.seen) {
      w.ended = ::waitpid(child, &w.status, WNOHANG);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  return w;
}

// Ctrl-C or a farm's kill midway: the run ends by that signal, and its output directory holds
// no report temporary (only finished reports would be there, and there are none yet).
TEST(CliCheck, KilledRunLeavesNoTemporaries) {
  TempDir tmp;
  link_long_drape_sequence(tmp.path() / "seq");
  for (int signal_number : {SIGINT, SIGTERM}) {
    const fs::path out = tmp.path() / ("out" + std::to_string(signal_number));
    // snag keeps a signal its caller ignores ignored (AnIgnoredInterruptStaysIgnored); a test
    // runner started in the background or under nohup passes SIGINT on ignored.
    const pid_t child = start_long_check(tmp.path(), out, {{signal_number, SIG_DFL}});
    ASSERT_GE(child, 0);
    TemporariesWait w = wait_for_temporaries(child, out);
    if (w.ended == 0) {
      ::kill(child, signal_number);
      ::waitpid(child, &w.status, 0);
    }
    EXPECT_TRUE(w.seen) << "the run ended before its temporaries were seen";
    EXPECT_TRUE(WIFSIGNALED(w.status) && WTERMSIG(w.status) == signal_number)
        << "signal " << signal_number << ", status " << w.status;
    EXPECT_EQ(report_temporaries(out), "") << "signal " << signal_number;
  }
}

// The hand-built sequence's topology changes at frame 2: the progress line says so, and the
// summary counts builds, rebuilds and topology changes in words that agree in number; under
// --rebuild always every frame is rebuilt (frames.csv's `rebuilt`).
TEST(CliCheck, ProgressAndSummaryCountTopologyChangesAndRebuilds) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult never = run_snag({"check", "seq", "--rebuild", "never"}, tmp.path());
  EXPECT_NE(never.err.find("[2/3] frame 2: 1 crossing, 0 touching (topology changed)\n"),
            std::string::npos)
      << never.err;
  EXPECT_NE(never.out.find("tree                 2 builds, 0 rebuilds (--rebuild never), "
                           "1 topology change\n"),
            std::string::npos)
      << never.out;
  const RunResult always =
      run_snag({"check", "seq", "--rebuild", "always", "--out", "a"}, tmp.path());
  EXPECT_NE(always.out.find("tree                 3 builds, 1 rebuild (--rebuild always)"),
            std::string::npos)
      << always.out;
  EXPECT_EQ(without_column(read_text(tmp.path() / "a" / "frames.csv"), "seconds"),
            "frame,file,triangles,pairs,crossing,touching,degenerate,uncertain,rebuilt,"
            "topology_changed\n"
            "1,seq/f.0001.obj,3,1,1,0,0,0,1,0\n"
            "2,seq/f.0002.obj,3,1,1,0,0,0,1,1\n"
            "3,seq/f.0003.obj,3,0,0,0,0,0,1,0\n");
}

// report.json's settings are what ran: --threads 0 resolved to every core (OpenMP's count,
// here OMP_NUM_THREADS), the --frames selection as given, or null without one.
TEST(CliCheck, ReportSettingsGiveTheThreadsAndFramesThatRan) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  RunResult zero;
  {
    const ScopedEnv threads("OMP_NUM_THREADS", "3");
    const ScopedEnv limit("OMP_THREAD_LIMIT", nullptr);  // a limit under 3 would cap the count
    zero =
        run_snag({"check", "seq", "--frames", "1-3x2", "--threads", "0", "--out", "z"}, tmp.path());
  }
  ASSERT_EQ(zero.status, 1) << context(zero);
  const auto z = nlohmann::json::parse(read_text(tmp.path() / "z" / "report.json"));
  EXPECT_EQ(z.at("settings").at("threads"), 3) << "--threads 0: every core (OMP_NUM_THREADS)";
  EXPECT_EQ(z.at("settings").at("frames"), "1-3x2");
  EXPECT_EQ(z.at("summary").at("frames_checked"), 2);
  run_snag({"check", "seq", "--out", "a"}, tmp.path());
  const auto a = nlohmann::json::parse(read_text(tmp.path() / "a" / "report.json"));
  EXPECT_TRUE(a.at("settings").at("frames").is_null());
}

// A sequence numbered on a grid of 2 that skips a number: the warning gives the step it counts
// by, so that "skips 6" is not read as a sequence of every number.
TEST(CliCheck, AGapWarningSaysTheStepItCountsBy) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const fs::path even = tmp.path() / "even";
  fs::create_directories(even);
  for (int f : {2, 4, 8})
    fs::copy_file(tmp.path() / "seq" / "f.0003.obj", even / ("f.000" + std::to_string(f) + ".obj"));
  const RunResult gap = run_snag({"check", "even"}, tmp.path());
  EXPECT_NE(gap.err.find("the sequence skips frame numbers 6 (between its first frame, 2, and "
                         "its last, 8, counting by 2)"),
            std::string::npos)
      << gap.err;
}

// A topology change re-welds, but the first frame's coincident-vertex warning (and count) is
// said once; a later topology without triangles is warned of like a first frame without any.
TEST(CliCheck, LaterTopologiesWarnOfEmptyFramesButNotAgainOfSeams) {
  TempDir tmp;
  fs::create_directories(tmp.path() / "seq");
  const std::string v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 1 1 0\nv 0 1 0\nv 0 0 0\n";
  write_text(tmp.path() / "seq" / "f.0001.obj", v + "f 1 2 3\nf 4 5 6\n");
  write_text(tmp.path() / "seq" / "f.0002.obj", v + "f 4 5 6\nf 1 2 3\n");  // reordered
  write_text(tmp.path() / "seq" / "f.0003.obj", v);                         // no faces
  const RunResult r = run_snag({"check", "seq", "--fail-on", "none", "--out", "o"}, tmp.path());
  EXPECT_EQ(r.status, 0) << context(r);
  size_t warnings = 0;
  for (size_t at = r.err.find("coincide"); at != std::string::npos;
       at = r.err.find("coincide", at + 1))
    ++warnings;
  EXPECT_EQ(warnings, 1u) << r.err;
  EXPECT_NE(r.err.find("seq/f.0003.obj: no triangles (6 vertices)"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(read_text(tmp.path() / "o" / "report.json"));
  EXPECT_EQ(j.at("inputs").at("coincident_vertices"), 2);
}

// A caller that ignores SIGINT (nohup, a background job) keeps it ignored: the run goes on (it
// is ended here by SIGTERM, or ends by itself), never by the interrupt.
TEST(CliCheck, AnIgnoredInterruptStaysIgnored) {
  TempDir tmp;
  link_long_drape_sequence(tmp.path() / "seq");
  const fs::path out = tmp.path() / "out";
  // SIGTERM at its default: the test ends the run with it.
  const pid_t child = start_long_check(tmp.path(), out, {{SIGINT, SIG_IGN}, {SIGTERM, SIG_DFL}});
  ASSERT_GE(child, 0);
  // Once the run is under way (its report temporaries are there), interrupt it.
  TemporariesWait w = wait_for_temporaries(child, out);
  ASSERT_EQ(w.ended, 0) << "the run ended before it was under way, status " << w.status;
  if (!w.seen) {
    ::kill(child, SIGKILL);
    ::waitpid(child, &w.status, 0);
    FAIL() << "the run's report temporaries did not appear within 30 s";
  }
  ::kill(child, SIGINT);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  int status = 0;
  const pid_t ended = ::waitpid(child, &status, WNOHANG);
  // Still going (then ended here), or finished its frames as if nothing had come.
  EXPECT_TRUE(ended == 0 || (WIFEXITED(status) && WEXITSTATUS(status) == 0))
      << "the run ended after an ignored SIGINT, status " << status;
  if (ended == 0) {
    ::kill(child, SIGTERM);
    ::waitpid(child, &status, 0);
  }
}

TEST(CliCheck, CoincidentVerticesWarnUnlessWelded) {
  // Two flat triangles side by side along their hypotenuse, each with its own copy of the seam's
  // two vertices (an unwelded seam): as separate vertices they touch along the seam; welded,
  // they share the edge and do not intersect.
  TempDir tmp;
  fs::create_directories(tmp.path() / "seam");
  write_text(tmp.path() / "seam" / "s.1.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 4 6 5\n");
  const RunResult plain =
      run_snag({"check", "seam", "--fail-on", "none", "--out", "a"}, tmp.path());
  EXPECT_EQ(plain.status, 0) << context(plain);
  EXPECT_NE(plain.err.find("2 vertices coincide exactly"), std::string::npos) << plain.err;
  EXPECT_NE(plain.err.find("--weld"), std::string::npos) << plain.err;
  EXPECT_EQ(read_text(tmp.path() / "a" / "pairs.csv"),
            "frame,face_a,face_b,kind,poly_a,poly_b\n1,0,1,touching,0,1\n");
  const auto a = nlohmann::json::parse(read_text(tmp.path() / "a" / "report.json"));
  EXPECT_EQ(a.at("inputs").at("coincident_vertices"), 2);

  const RunResult welded =
      run_snag({"check", "seam", "--weld", "1e-6", "--fail-on", "any", "--out", "b"}, tmp.path());
  EXPECT_EQ(welded.status, 0) << context(welded);
  EXPECT_EQ(welded.err.find("coincide"), std::string::npos) << welded.err;
  EXPECT_EQ(read_text(tmp.path() / "b" / "pairs.csv"), "frame,face_a,face_b,kind,poly_a,poly_b\n");
  const auto b = nlohmann::json::parse(read_text(tmp.path() / "b" / "report.json"));
  EXPECT_EQ(b.at("inputs").at("welded_vertices"), 2);
  EXPECT_DOUBLE_EQ(b.at("settings").at("weld").get<double>(), 1e-6);
}

// --baseline: pairs an earlier run found, accepted; only the others fail the run.

/// pairs.csv's data rows, each cut to its first six columns (the pair as any run reports it).
std::vector<std::string> pair_rows(const std::string& pairs_csv) {
  std::vector<std::string> rows;
  const auto parsed = parse_csv(pairs_csv);
  for (size_t i = 1; i < parsed.size(); ++i) {
    std::string row;
    for (size_t c = 0; c < 6; ++c) row += (c ? "," : "") + parsed[i].at(c);
    rows.push_back(row);
  }
  return rows;
}

TEST(CliBaseline, TheDrapesPairsLessSomeFailOnExactlyThoseLeftOut) {
  TempDir tmp;
  const std::string drape = (source_dir() / "samples" / "drape").string();
  const RunResult first = run_snag({"check", drape, "--out", "first", "-q"}, tmp.path());
  ASSERT_EQ(first.status, 1) << context(first);
  const std::string found = read_text(tmp.path() / "first" / "pairs.csv");
  const std::vector<std::string> rows = pair_rows(found);
  ASSERT_GT(rows.size(), 1000u);

  // Every pair accepted: the run passes even with --fail-on any, and nothing is new.
  const RunResult all = run_snag(
      {"check", drape, "--fail-on", "any", "--baseline", "first/pairs.csv", "--out", "all"},
      tmp.path());
  EXPECT_EQ(all.status, 0) << context(all);
  const std::string count = std::to_string(rows.size());
  EXPECT_NE(all.out.find("baseline             first/pairs.csv: " + count + " entries, " + count +
                         " for the frames checked, 0 matched no pair\n"),
            std::string::npos)
      << all.out;
  EXPECT_NE(all.out.find("new pairs            0\n"), std::string::npos) << all.out;

  // Every 97th row left out (the file cut by hand, header kept): those pairs are new, and only
  // those; the reports still list every pair, the same rows as without a baseline.
  std::string cut = "frame,face_a,face_b,kind,poly_a,poly_b\n";
  std::vector<std::string> left_out;
  int64_t left_out_crossing = 0;
  std::set<std::string> new_frames;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (i % 97 == 40) {
      left_out.push_back(rows[i]);
      left_out_crossing += rows[i].find(",crossing,") != std::string::npos;
      new_frames.insert(rows[i].substr(0, rows[i].find(',')));
      continue;
    }
    cut += rows[i] + "\n";
  }
  write_text(tmp.path() / "cut.csv", cut);
  const RunResult r =
      run_snag({"check", drape, "--baseline", "cut.csv", "--out", "second"}, tmp.path());
  ASSERT_EQ(r.status, left_out_crossing > 0 ? 1 : 0) << context(r);
  const std::string second = read_text(tmp.path() / "second" / "pairs.csv");
  EXPECT_EQ(pair_rows(second), rows);
  const auto parsed = parse_csv(second);
  ASSERT_EQ(parsed.at(0).back(), "accepted");
  std::vector<std::string> marked_new;
  for (size_t i = 1; i < parsed.size(); ++i) {
    ASSERT_EQ(parsed[i].size(), 7u);
    if (parsed[i][6] == "0")
      marked_new.push_back(rows[i - 1]);
    else
      EXPECT_EQ(parsed[i][6], "1");
  }
  EXPECT_EQ(marked_new, left_out);

  const int64_t new_pairs = static_cast<int64_t>(left_out.size());
  EXPECT_NE(r.out.find("new pairs            " + std::to_string(new_pairs) + " (" +
                       std::to_string(left_out_crossing) + " crossing, " +
                       std::to_string(new_pairs - left_out_crossing) + " touching) in " +
                       std::to_string(new_frames.size()) + " frames, the first in frame " +
                       left_out.front().substr(0, left_out.front().find(',')) + "\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("new intersections found, not in the baseline (--fail-on crossing)"),
            std::string::npos)
      << r.err;
  // frames.csv counts each frame's accepted pairs; report.json says what the baseline did.
  const auto frames = parse_csv(read_text(tmp.path() / "second" / "frames.csv"));
  ASSERT_EQ(frames.at(0).back(), "accepted");
  int64_t accepted = 0;
  for (size_t i = 1; i < frames.size(); ++i) accepted += std::stoll(frames[i].back());
  EXPECT_EQ(accepted, static_cast<int64_t>(rows.size()) - new_pairs);
  const auto j = nlohmann::json::parse(read_text(tmp.path() / "second" / "report.json"));
  EXPECT_EQ(j.at("settings").at("baseline"), "cut.csv");
  EXPECT_EQ(j.at("inputs").at("baseline").at("entries"), rows.size() - left_out.size());
  EXPECT_EQ(j.at("inputs").at("baseline").at("unmatched"), 0);
  EXPECT_EQ(j.at("summary").at("new_pairs"), new_pairs);
  EXPECT_EQ(j.at("summary").at("new_crossing"), left_out_crossing);
  EXPECT_EQ(j.at("summary").at("failed"), left_out_crossing > 0);

  // That run's pairs.csv as the next baseline: its new pairs are marked 0 and stay new until
  // someone marks them 1 (or takes the pairs of a run without a baseline).
  const RunResult next = run_snag(
      {"check", drape, "--baseline", "second/pairs.csv", "--fail-on", "any", "-q"}, tmp.path());
  EXPECT_EQ(next.status, 1) << context(next);
  EXPECT_NE(next.out.find("second/pairs.csv: " + std::to_string(rows.size() - left_out.size()) +
                          " entries (" + std::to_string(left_out.size()) +
                          " rows marked accepted 0 left out)"),
            std::string::npos)
      << next.out;
  EXPECT_NE(next.out.find("new pairs            " + std::to_string(new_pairs) + " ("),
            std::string::npos)
      << next.out;
}

TEST(CliBaseline, HandWrittenRowsForEveryFrameAndByKind) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  // Frame 1's crossing is (1, 2), frame 2's (0, 2) after the faces are reordered.
  write_text(tmp.path() / "every.csv", "face_b,face_a,frame\n2,1,*\n");
  const RunResult every = run_snag({"check", "seq", "--baseline", "every.csv"}, tmp.path());
  EXPECT_EQ(every.status, 1) << context(every);
  EXPECT_NE(every.out.find("new pairs            1 (1 crossing, 0 touching) in 1 frame, the "
                           "first in frame 2\nfirst failing frame  2\n"),
            std::string::npos)
      << every.out;
  EXPECT_NE(every.err.find("[1/3] frame 1: 1 crossing, 0 touching, 1 accepted"), std::string::npos)
      << every.err;
  // Frame 2 reorders the faces: the ids of a baseline may now name other faces.
  EXPECT_NE(every.err.find("snag: warning: frame 2 has another face list than the frame before: "
                           "the --baseline's face ids may name other faces from there on"),
            std::string::npos)
      << every.err;

  write_text(tmp.path() / "both.csv", "frame,face_a,face_b\n1,1,2\n2,0,2\n7,0,1\n");
  const RunResult both = run_snag({"check", "seq", "--baseline", "both.csv"}, tmp.path());
  EXPECT_EQ(both.status, 0) << context(both);
  // Frame 7 is not checked: its entry is not counted among the frames checked.
  EXPECT_NE(both.out.find("both.csv: 3 entries, 2 for the frames checked, 0 matched no pair\n"),
            std::string::npos)
      << both.out;

  // Accepted while it touches, it crosses: new, and its entry matched nothing.
  write_text(tmp.path() / "touching.csv",
             "frame,face_a,face_b,kind\n1,1,2,touching\n2,0,2,crossing\n");
  const RunResult touching = run_snag({"check", "seq", "--baseline", "touching.csv"}, tmp.path());
  EXPECT_EQ(touching.status, 1) << context(touching);
  EXPECT_NE(touching.out.find("2 entries, 2 for the frames checked, 1 matched no pair (line 2)\n"),
            std::string::npos)
      << touching.out;

  // Six entries that match nothing: the first five lines are named. A fourth frame puts the
  // faces back in frame 1's order, a second change of the face list, warned of once only.
  write_text(tmp.path() / "seq" / "f.0004.obj",
             std::string(quad_vertices) + b_away + "f 1 2 3 4\nf 5 6 7\n");
  write_text(tmp.path() / "stale.csv",
             "frame,face_a,face_b\n3,0,1\n3,0,2\n3,1,2\n2,0,1\n2,1,2\n4,0,1\n");
  const RunResult stale = run_snag({"check", "seq", "--baseline", "stale.csv"}, tmp.path());
  EXPECT_EQ(stale.status, 1) << context(stale);
  EXPECT_NE(stale.out.find("6 entries, 6 for the frames checked, 6 matched no pair (lines 2, 3, "
                           "4, 5, 6, ...)\n"),
            std::string::npos)
      << stale.out;
  const std::string warning = "has another face list than the frame before";
  const size_t at = stale.err.find(warning);
  EXPECT_NE(at, std::string::npos) << stale.err;
  EXPECT_EQ(stale.err.find(warning, at + 1), std::string::npos) << stale.err;
  EXPECT_NE(stale.err.find("[4/4] frame 4: clean (topology changed)"), std::string::npos)
      << stale.err;
}

TEST(CliBaseline, ABadBaselineExitsThreeBeforeAnyFrameAndWritesNoReport) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  write_text(tmp.path() / "bad.csv", "frame,face_a,face_b\n1,1,2\n2,0,two\n");
  const RunResult bad =
      run_snag({"check", "seq", "--baseline", "bad.csv", "--out", "out"}, tmp.path());
  EXPECT_EQ(bad.status, 3) << context(bad);
  EXPECT_NE(bad.err.find("bad.csv:3: face_b: expected a face id (a whole number >= 0), got 'two'"),
            std::string::npos)
      << bad.err;
  EXPECT_EQ(bad.err.find("frame 1"), std::string::npos) << "no frame is checked: " << bad.err;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));

  const RunResult missing = run_snag({"check", "seq", "--baseline", "none.csv"}, tmp.path());
  EXPECT_EQ(missing.status, 3) << context(missing);
  EXPECT_NE(missing.err.find("none.csv"), std::string::npos) << missing.err;

  // A face the mesh does not have: found at the first frame it applies to.
  write_text(tmp.path() / "far.csv", "frame,face_a,face_b\n*,0,99\n");
  const RunResult far =
      run_snag({"check", "seq", "--baseline", "far.csv", "--out", "out"}, tmp.path());
  EXPECT_EQ(far.status, 3) << context(far);
  EXPECT_NE(far.err.find("far.csv:2: face 99 is not a face of frame 1 (3 triangles)"),
            std::string::npos)
      << far.err;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));

  // A scene run's pairs.csv given to a run of one mesh.
  write_text(tmp.path() / "scene.csv",
             "frame,face_a,face_b,kind,poly_a,poly_b,object_a,object_b\n1,0,0,crossing,0,0,a,b\n");
  const RunResult scene = run_snag({"check", "seq", "--baseline", "scene.csv"}, tmp.path());
  EXPECT_EQ(scene.status, 3) << context(scene);
  EXPECT_NE(scene.err.find("scene.csv:1: object_a and object_b columns, but this run checks one "
                           "mesh"),
            std::string::npos)
      << scene.err;
  EXPECT_EQ(run_snag({"check", "seq", "--baseline", ""}, tmp.path()).status, 2);
}

// --junit: a JUnit XML report beside the others, for a CI server's test view.
TEST(CliCheck, AJunitReportHasAFailingCasePerFailingFrame) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult r = run_snag({"check", "seq", "--junit", "ci/snag.xml", "-q"}, tmp.path());
  EXPECT_EQ(r.status, 1) << context(r);
  const std::string xml = read_text(tmp.path() / "ci" / "snag.xml");
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"snag check\" "
                      "tests=\"3\" failures=\"2\"",
                      0),
            0u)
      << xml;
  EXPECT_NE(xml.find("<testsuite name=\"seq\" tests=\"3\" failures=\"2\""), std::string::npos)
      << xml;
  // Frames 1 and 2 cross (the pair as pairs.csv gives it), frame 3 is clean.
  EXPECT_NE(xml.find("name=\"frame 1: seq/f.0001.obj\" time=\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<failure type=\"crossing\" message=\"1 crossing pair (--fail-on "
                     "crossing)\">frame,face_a,face_b,kind,poly_a,poly_b\n1,1,2,crossing,0,1\n"
                     "</failure>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("\n2,0,2,crossing,0,1\n</failure>"), std::string::npos) << xml;
  const size_t third = xml.find("name=\"frame 3: seq/f.0003.obj\"");
  ASSERT_NE(third, std::string::npos) << xml;
  EXPECT_EQ(xml.find("<failure", third), std::string::npos) << xml;
  EXPECT_EQ(directory_entries(tmp.path() / "ci"), std::vector<std::string>{"snag.xml"});

  // With frame 1's pair accepted, only frame 2 fails.
  write_text(tmp.path() / "accepted.csv", "frame,face_a,face_b\n1,1,2\n");
  EXPECT_EQ(run_snag({"check", "seq", "--junit", "ci/snag.xml", "--baseline", "accepted.csv", "-q"},
                     tmp.path())
                .status,
            1);
  EXPECT_NE(read_text(tmp.path() / "ci" / "snag.xml").find("failures=\"1\""), std::string::npos);

  // A run that fails on a bad frame writes none, and removes the directory it made for it.
  write_text(tmp.path() / "seq" / "f.0004.obj", "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n");
  const RunResult bad = run_snag({"check", "seq", "--junit", "new/snag.xml"}, tmp.path());
  EXPECT_EQ(bad.status, 3) << context(bad);
  EXPECT_FALSE(fs::exists(tmp.path() / "new"));
  fs::remove(tmp.path() / "seq" / "f.0004.obj");

  // Under --fail-on any the failures say so.
  EXPECT_EQ(
      run_snag({"check", "seq", "--junit", "ci/any.xml", "--fail-on", "any", "-q"}, tmp.path())
          .status,
      1);
  EXPECT_NE(read_text(tmp.path() / "ci" / "any.xml")
                .find("<failure type=\"any\" message=\"1 intersecting pair (--fail-on any)\">"),
            std::string::npos);

  // Refused before any frame, nothing replaced: no file name, standard output's "-", a
  // directory or a link in its place, a file the run reads or writes, a directory that
  // cannot be made.
  write_text(tmp.path() / "accepted.csv", "frame,face_a,face_b\n1,1,2\n");
  fs::create_directory(tmp.path() / "out");
  write_text(tmp.path() / "out" / "pairs.csv", "earlier\n");
  fs::create_symlink("elsewhere.xml", tmp.path() / "link.xml");
  write_text(tmp.path() / "a-file", "x");
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused = {
      {{"--junit", "ci"}, "ci: a directory; --junit writes a new file in its place"},
      {{"--junit", "new/"}, "new/: not a file name"},
      {{"--junit", "ci/.."}, "ci/..: not a file name"},
      {{"--junit", "-"}, "-: not a file name"},
      {{"--junit", "link.xml"}, "link.xml: a symbolic link"},
      {{"--junit", "accepted.csv", "--baseline", "accepted.csv"},
       "accepted.csv: is the --baseline; --junit would replace it"},
      {{"--junit", "out/pairs.csv", "--out", "out"},
       "out/pairs.csv: is a report of --out; --junit would replace it"},
      {{"--junit", "seq/../seq/f.0002.obj"}, "is a frame of seq; --junit would replace it"},
      {{"--junit", "a-file/snag.xml"}, "a-file"},
  };
  for (const auto& [args, says] : refused) {
    std::vector<std::string> all = {"check", "seq"};
    all.insert(all.end(), args.begin(), args.end());
    const RunResult r = run_snag(all, tmp.path());
    EXPECT_EQ(r.status, 3) << context(r);
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("frame 1"), std::string::npos) << "a frame was checked: " << r.err;
  }
  EXPECT_EQ(read_text(tmp.path() / "out" / "pairs.csv"), "earlier\n");
  EXPECT_EQ(read_text(tmp.path() / "accepted.csv"), "frame,face_a,face_b\n1,1,2\n");
  EXPECT_TRUE(fs::is_symlink(tmp.path() / "link.xml"));
  EXPECT_FALSE(fs::exists(tmp.path() / "new"));
}

TEST(CliStatus, UsageErrorsExitTwo) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const std::vector<std::vector<std::string>> cases = {
      {},
      {"frobnicate"},
      {"check"},
      {"check", "seq", "--bogus"},
      {"check", "seq", "--rebuild", "sometimes"},
      {"check", "seq", "--fail-on", "all"},
      {"check", "seq", "--backend", "gpu"},
      {"check", "seq", "--threads", "-1"},
      {"check", "seq", "--threads", "100000"},  // crashed the run before it was capped
      {"check", "seq", "--rebuild-threshold", "nan"},
      {"check", "seq", "--rebuild-threshold", "0.5"},
      {"check", "seq", "--weld", "-0.5"},
      {"check", "seq", "--frames", "abc"},
      {"check", "seq", "--frames", "100-200"},
      {"check", "seq", "--frames", ""},
      {"check", "seq", "--out", ""},
      {"check", "seq", "--out", "-q"},  // wrote the reports into ./-q
      {"bench"},
  };
  for (const auto& args : cases) {
    std::string line;
    for (const auto& a : args) line += " " + a;
    const RunResult r = run_snag(args, tmp.path());
    EXPECT_EQ(r.status, 2) << "snag" << line << "\n" << context(r);
    EXPECT_FALSE(r.err.empty()) << "snag" << line << " says nothing";
    EXPECT_EQ(r.err.rfind("snag: error: ", 0), 0u) << "snag" << line << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "-q"));
  const RunResult dashed = run_snag({"check", "seq", "--out", "./-q", "-q"}, tmp.path());
  EXPECT_EQ(dashed.status, 1) << context(dashed);
  EXPECT_TRUE(fs::exists(tmp.path() / "-q" / "pairs.csv"));
  // A word that names no command is named (and its --help is no help that exits 0).
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"report"}, std::vector<std::string>{"report", "--help"}}) {
    const RunResult r = run_snag(args, tmp.path());
    EXPECT_EQ(r.status, 2) << context(r);
    EXPECT_NE(r.err.find("unknown command 'report'; expected check or bench"), std::string::npos)
        << r.err;
  }
}

// Each usage error says what was expected and what was found, in words (not CLI11's "A
// subcommand is required", "Value abc not in range 0 to 4096" or "Could not convert").
TEST(CliStatus, UsageErrorsSayWhatWasExpected) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{}, "snag: error: expected a command, check or bench, found nothing\n"},
      {{"--bogus"}, "expected a command, check or bench, found the option --bogus\n"},
      {{"bench"}, "bench: expected a command, cpu, gpu, accuracy, io or scene, found nothing"},
      {{"bench", "foo"}, "bench: expected a command, cpu, gpu, accuracy, io or scene, found 'foo'"},
      {{"check", "seq", "--threads", "abc"},
       "--threads: expected a whole number from 0 to 4096, got 'abc'"},
      {{"check", "seq", "--threads", "1.5"},
       "--threads: expected a whole number from 0 to 4096, got '1.5'"},
      {{"check", "seq", "--device", "1.5"}, "--device: expected a whole number >= 0, got '1.5'"},
      {{"check", "seq", "--rebuild-threshold", "abc"},
       "--rebuild-threshold: expected a number, got 'abc'"},
      {{"check", "seq", "--rebuild-threshold", "0.5"},
       "--rebuild-threshold: expected a number >= 1, got '0.5'"},
      {{"check", "seq", "--obstacle", "-q"},
       "--obstacle: expected a sequence, found the option -q (write ./-q for one of that name)"},
      {{"check", "--scene", "-q"}, "--scene: expected a scene file, found the option -q"},
      {{"bench", "cpu", "--frames", "2.5"}, "--frames: expected a whole number >= 1, got '2.5'"},
      {{"bench", "cpu", "--sizes", "2244,x"}, "--sizes: expected a whole number >= 0, got 'x'"},
  };
  for (const auto& [args, expected] : cases) {
    std::string line;
    for (const auto& a : args) line += " " + a;
    const RunResult r = run_snag(args, tmp.path());
    EXPECT_EQ(r.status, 2) << "snag" << line << "\n" << context(r);
    EXPECT_NE(r.err.find(expected), std::string::npos) << "snag" << line << ": " << r.err;
    EXPECT_NE(r.err.find("Run with --help for more information."), std::string::npos) << r.err;
  }
}

// An option given twice takes its last value (a wrapper script appending its overrides);
// repeatable options keep each value.
TEST(CliStatus, RepeatedOptionsTakeTheirLastValue) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");  // crossings: status 1 under --fail-on crossing
  const RunResult none_last =
      run_snag({"check", "seq", "--fail-on", "crossing", "--fail-on", "none", "-q"}, tmp.path());
  EXPECT_EQ(none_last.status, 0) << context(none_last);
  const RunResult crossing_last = run_snag(
      {"check", "seq", "--fail-on", "none", "--fail-on", "crossing", "--out", "a", "--out", "b"},
      tmp.path());
  EXPECT_EQ(crossing_last.status, 1) << context(crossing_last);
  EXPECT_FALSE(fs::exists(tmp.path() / "a"));
  EXPECT_TRUE(fs::exists(tmp.path() / "b" / "pairs.csv"));
}

TEST(CliStatus, CudaBackendRunsOrExitsFourWithAReason) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const RunResult r = run_snag({"check", "seq", "--backend", "cuda"}, tmp.path());
  if (r.status == 4) {
    // Not built with CUDA, or no device here: said plainly.
    EXPECT_NE(r.err.find("--backend cuda"), std::string::npos) << r.err;
    EXPECT_TRUE(r.err.find("built without the CUDA backend") != std::string::npos ||
                r.err.find("no CUDA device") != std::string::npos)
        << r.err;
  } else {
    EXPECT_EQ(r.status, 1) << context(r);  // a GPU is here: the sequence has a crossing
  }
  const RunResult bad =
      run_snag({"check", "seq", "--backend", "cuda", "--device", "999"}, tmp.path());
  EXPECT_EQ(bad.status, 4) << context(bad);
  EXPECT_FALSE(bad.err.empty());
}

TEST(CliStatus, HelpAndVersionExitZero) {
  TempDir tmp;
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--help"},
                                               {"check", "--help"},
                                               {"bench", "cpu", "--help"},
                                               {"bench", "gpu", "--help"},
                                               {"bench", "io", "--help"},
                                               {"bench", "scene", "--help"},
                                               {"--version"}}) {
    const RunResult r = run_snag(args, tmp.path());
    EXPECT_EQ(r.status, 0) << args[0] << "\n" << context(r);
    EXPECT_FALSE(r.out.empty());
  }
}

// --version names the build's CUDA backend (or its absence) on a second line, so that a bug
// report says what was built.
TEST(CliStatus, VersionSaysWhatTheCudaBackendWasBuiltFor) {
  TempDir tmp;
  const RunResult r = run_snag({"--version"}, tmp.path());
  ASSERT_EQ(r.status, 0) << context(r);
  EXPECT_EQ(r.out.rfind("snag ", 0), 0u) << r.out;
#ifdef SNAG_EXPECTED_CUDA_ARCHITECTURES
  EXPECT_NE(r.out.find(std::string("\nCUDA backend: architectures ") +
                       SNAG_EXPECTED_CUDA_ARCHITECTURES + "; CUDA runtime "),
            std::string::npos)
      << r.out;
#else
  EXPECT_NE(r.out.find("\nCUDA backend: not built ("), std::string::npos) << r.out;
#endif
}

TEST(CliStatus, MalformedObjExitsThreeAndLeavesNoReport) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  // A frame after two good ones: the error is found late, and still no report appears.
  write_text(tmp.path() / "seq" / "f.0004.obj", "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n");
  const RunResult r = run_snag({"check", "seq", "--out", "out"}, tmp.path());
  EXPECT_EQ(r.status, 3) << context(r);
  EXPECT_NE(r.err.find("f.0004.obj:3"), std::string::npos) << r.err;
  // The directories the run made for its reports go with them; one that was there stays.
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
  const RunResult nested = run_snag({"check", "seq", "--out", "new/reports/"}, tmp.path());
  EXPECT_EQ(nested.status, 3) << context(nested);
  EXPECT_FALSE(fs::exists(tmp.path() / "new"));
  fs::create_directory(tmp.path() / "there");
  EXPECT_EQ(run_snag({"check", "seq", "--out", "there/reports"}, tmp.path()).status, 3);
  EXPECT_EQ(directory_entries(tmp.path() / "there"), std::vector<std::string>{});
  EXPECT_TRUE(fs::is_directory(tmp.path() / "there"));
}

TEST(CliStatus, BadFrameInTheMiddleKeepsTheEarlierReports) {
  TempDir tmp;
  const fs::path seq = write_hand_built_sequence(tmp.path() / "seq");
  const RunResult first = run_snag({"check", "seq", "--out", "out"}, tmp.path());
  ASSERT_EQ(first.status, 1) << context(first);
  const std::vector<std::string> reports = {"frames.csv", "pairs.csv", "report.json"};
  ASSERT_EQ(directory_entries(tmp.path() / "out"), reports);
  std::vector<std::string> earlier;
  for (const std::string& name : reports) earlier.push_back(read_text(tmp.path() / "out" / name));

  // Frame 2 of 4 is malformed: frame 1 was already written to the reports' temporaries when
  // it is found, and frames 3 and 4 are read ahead of it.
  write_text(seq / "f.0002.obj", "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n");
  write_text(seq / "f.0004.obj", read_text(seq / "f.0003.obj"));
  const RunResult r = run_snag({"check", "seq", "--out", "out"}, tmp.path());
  EXPECT_EQ(r.status, 3) << context(r);
  EXPECT_NE(r.err.find("f.0002.obj:3"), std::string::npos) << r.err;
  // No temporary left (the listing shows hidden files) and the earlier run's bytes unchanged.
  EXPECT_EQ(directory_entries(tmp.path() / "out"), reports);
  for (size_t i = 0; i < reports.size(); ++i)
    EXPECT_EQ(read_text(tmp.path() / "out" / reports[i]), earlier[i]) << reports[i];
}

TEST(CliStatus, VertexCountChangeExitsThree) {
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  write_text(tmp.path() / "seq" / "f.0004.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const RunResult r = run_snag({"check", "seq", "--out", "out"}, tmp.path());
  EXPECT_EQ(r.status, 3) << context(r);
  EXPECT_NE(r.err.find("f.0004.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 vertices"), std::string::npos) << r.err;
  if (fs::exists(tmp.path() / "out"))
    EXPECT_EQ(directory_entries(tmp.path() / "out"), std::vector<std::string>{});
}

TEST(CliStatus, MissingSequenceAndUnwritableOutExitThree) {
  TempDir tmp;
  EXPECT_EQ(run_snag({"check", "nowhere/f.%04d.obj"}, tmp.path()).status, 3);
  write_hand_built_sequence(tmp.path() / "seq");
  write_text(tmp.path() / "a-file", "x");
  const RunResult r = run_snag({"check", "seq", "--out", "a-file"}, tmp.path());
  EXPECT_EQ(r.status, 3) << context(r);
  EXPECT_NE(r.err.find("not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(tmp.path() / "a-file"), "x");
}

// A summary that cannot be written (standard output on a full disk) fails the run, after the
// reports it could write; so does help that cannot be.
TEST(CliStatus, AnUnwritableStandardOutputExitsThree) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  TempDir tmp;
  write_hand_built_sequence(tmp.path() / "seq");
  const auto run_into_full = [&](const std::string& args) {
    const std::string command = "cd '" + tmp.path().string() + "' && '" +
                                snag_executable().string() + "' " + args + " >/dev/full 2>err.txt";
    const int status = std::system(command.c_str());
    EXPECT_TRUE(WIFEXITED(status)) << command;
    return WEXITSTATUS(status);
  };
  EXPECT_EQ(run_into_full("check seq --fail-on none --out out"), 3);
  EXPECT_NE(read_text(tmp.path() / "err.txt").find("snag: cannot write to standard output"),
            std::string::npos)
      << read_text(tmp.path() / "err.txt");
  EXPECT_TRUE(fs::exists(tmp.path() / "out" / "report.json"));
  EXPECT_EQ(run_into_full("check --help"), 3);
  // To a writable place, the same runs succeed.
  EXPECT_EQ(run_snag({"check", "seq", "--fail-on", "none", "-q"}, tmp.path()).status, 0);
}

/// Long and short options named in `text`: "--word" and " -x".
std::set<std::string> options_in(const std::string& text) {
  std::set<std::string> found;
  const std::regex option(R"((^|[\s,\[])(--[a-z][a-z-]*|-[a-zA-Z])\b)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), option);
       it != std::sregex_iterator(); ++it)
    found.insert((*it)[2]);
  return found;
}

/// The man page's section for one command (`.SS "snag check` up to the next .SS or .SH),
/// with roff's escaped hyphens made plain.
std::string man_section(const std::string& man, const std::string& heading) {
  const size_t start = man.find(".SS \"" + heading);
  if (start == std::string::npos) return {};
  size_t end = man.find("\n.S", start + 1);
  std::string section =
      man.substr(start, end == std::string::npos ? std::string::npos : end - start);
  return std::regex_replace(section, std::regex(R"(\\-)"), "-");
}

TEST(CliHelp, AgreesWithTheManPage) {
  const std::string man = read_text(source_dir() / "man" / "snag.1");
  TempDir tmp;
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands = {
      {"snag check", {"check", "--help"}},
      {"snag bench cpu", {"bench", "cpu", "--help"}},
      {"snag bench gpu", {"bench", "gpu", "--help"}},
      {"snag bench accuracy", {"bench", "accuracy", "--help"}},
      {"snag bench io", {"bench", "io", "--help"}},
      {"snag bench scene", {"bench", "scene", "--help"}},
  };
  for (const auto& [heading, args] : commands) {
    const std::string section = man_section(man, heading);
    ASSERT_FALSE(section.empty()) << "man/snag.1 has no .SS \"" << heading << "\" section";
    const RunResult help = run_snag(args, tmp.path());
    ASSERT_EQ(help.status, 0);
    std::set<std::string> in_help = options_in(help.out);
    in_help.erase("-h");
    in_help.erase("--help");
    std::set<std::string> in_man = options_in(section);
    in_man.erase("-h");
    in_man.erase("--help");
    EXPECT_EQ(in_help, in_man) << heading << ": `snag " << args[0]
                               << " --help` and man/snag.1 list "
                               << "different options";
  }
  // Every exit status in the man page.
  for (const char* status : {".B 0", ".B 1", ".B 2", ".B 3", ".B 4"})
    EXPECT_NE(man.find(std::string(".TP\n") + status), std::string::npos) << status;
}

}  // namespace
}  // namespace snag::test
