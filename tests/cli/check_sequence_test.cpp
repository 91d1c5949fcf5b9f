// The frame loop of `snag check` (cli/check_sequence.cpp) run in-process on the CPU backend,
// both ways it hands records on: from the calling thread (the CPU's way) and from a recording
// thread one frame behind the checks (a GPU's way, taken here with `gpu` set and a CPU
// checker). The records are checked against each frame checked on its own, in order, and
// errors against the frames handed on before them.
#include "cli/check_sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli/run_snag.h"
#include "snag/detect/cpu_backend.h"
#include "snag/detect/resolve.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/scene/scene.h"
#include "snag/seq/sequence.h"
#include "test_paths.h"

namespace snag::cli {
namespace {

namespace fs = std::filesystem;

std::unique_ptr<detect::Checker> cpu_checker() {
  return std::make_unique<detect::Checker>(detect::make_cpu_backend(2),
                                           detect::make_rounded_resolver());
}

std::vector<seq::Frame> drape_frames() {
  return seq::resolve_sequence((snag::test::source_dir() / "samples" / "drape").string());
}

/// What on_frame saw: the records in order, the threads it ran on, and whether two calls
/// ever overlapped.
struct Handed {
  std::vector<report::FrameRecord> records;
  std::vector<std::thread::id> threads;
  std::atomic<int> inside{0};
  bool overlapped = false;

  void take(report::FrameRecord&& record) {
    if (inside.fetch_add(1) != 0) overlapped = true;
    threads.push_back(std::this_thread::get_id());
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // a slow report writer
    records.push_back(std::move(record));
    inside.fetch_sub(1);
  }
};

SequenceSettings settings_for(bool beside) {
  SequenceSettings settings;
  settings.threads = 3;
  settings.gpu = beside;  // a GPU's loop records beside the checks
  return settings;
}

TEST(CheckSequence, RecordsAreEachFramesOwnCheckInOrderBothWays) {
  const std::vector<seq::Frame> frames = drape_frames();
  ASSERT_GE(frames.size(), 10u);
  // The reference: every frame read and checked on its own.
  std::vector<std::vector<detect::FacePair>> expected;
  {
    const std::unique_ptr<detect::Checker> checker = cpu_checker();
    for (const seq::Frame& f : frames) {
      const mesh::Mesh mesh = io::read_mesh(f.path);
      if (expected.empty())
        checker->set_triangles(mesh.triangles, static_cast<int32_t>(mesh.positions.size()));
      expected.push_back(checker->check(mesh.positions).pairs);
    }
  }
  size_t frames_with_pairs = 0;
  for (const auto& pairs : expected) frames_with_pairs += !pairs.empty();
  ASSERT_GT(frames_with_pairs, 0u) << "the sample should fold through itself";

  for (const bool beside : {false, true}) {
    SCOPED_TRACE(beside ? "records beside the checks" : "records on the loop's thread");
    const std::unique_ptr<detect::Checker> checker = cpu_checker();
    report::Inputs inputs;
    Handed handed;
    LoopTimes times;
    SequenceSettings settings = settings_for(beside);
    settings.times = &times;
    check_sequence(
        frames, *checker, settings, inputs,
        [&](report::FrameRecord&& r) { handed.take(std::move(r)); }, [](const std::string&) {});
    ASSERT_EQ(handed.records.size(), frames.size());
    EXPECT_FALSE(handed.overlapped);
    for (size_t i = 0; i < frames.size(); ++i) {
      const report::FrameRecord& r = handed.records[i];
      EXPECT_EQ(r.frame, frames[i].number);
      ASSERT_EQ(r.pairs.size(), expected[i].size()) << "frame " << r.frame;
      for (size_t k = 0; k < r.pairs.size(); ++k) {
        EXPECT_EQ(r.pairs[k].a, expected[i][k].a);
        EXPECT_EQ(r.pairs[k].b, expected[i][k].b);
        EXPECT_EQ(r.pairs[k].kind, expected[i][k].kind);
      }
    }
    for (const std::thread::id id : handed.threads)
      EXPECT_EQ(id != std::this_thread::get_id(), beside);
    EXPECT_GT(times.recording + times.handing, 0.0);
    if (!beside) EXPECT_EQ(times.behind, 0.0);
  }
}

/// The drape frames copied into `dir`, the text of the i-th (from 0) changed by edit(i, text).
std::vector<seq::Frame> drape_copies(const fs::path& dir,
                                     const std::function<void(size_t, std::string&)>& edit) {
  const std::vector<seq::Frame> frames = drape_frames();
  for (size_t i = 0; i < frames.size(); ++i) {
    std::string text = snag::test::read_text(frames[i].path);
    edit(i, text);
    snag::test::write_text(dir / frames[i].path.filename(), text);
  }
  return seq::resolve_sequence(dir.string());
}

TEST(CheckSequence, ABadFrameIsThrownAfterEveryFrameBeforeItIsHandedOn) {
  // The 5th frame's copy gets a face that names a vertex the file does not have.
  const snag::test::TempDir dir;
  const std::vector<seq::Frame> frames = drape_copies(dir.path(), [](size_t i, std::string& text) {
    if (i == 4) text += "f 1 2 999999\n";
  });
  for (const bool beside : {false, true}) {
    SCOPED_TRACE(beside ? "records beside the checks" : "records on the loop's thread");
    const std::unique_ptr<detect::Checker> checker = cpu_checker();
    report::Inputs inputs;
    Handed handed;
    try {
      check_sequence(
          frames, *checker, settings_for(beside), inputs,
          [&](report::FrameRecord&& r) { handed.take(std::move(r)); }, [](const std::string&) {});
      FAIL() << "the bad frame was not reported";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(frames[4].path.filename().string()), std::string::npos)
          << e.what();
    }
    ASSERT_EQ(handed.records.size(), 4u);
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(handed.records[i].frame, frames[i].number);
  }
}

TEST(CheckSequence, AReportWritersErrorStopsTheRunAndIsThrown) {
  const std::vector<seq::Frame> frames = drape_frames();
  for (const bool beside : {false, true}) {
    SCOPED_TRACE(beside ? "records beside the checks" : "records on the loop's thread");
    const std::unique_ptr<detect::Checker> checker = cpu_checker();
    report::Inputs inputs;
    int handed = 0;
    EXPECT_THROW(check_sequence(
                     frames, *checker, settings_for(beside), inputs,
                     [&](report::FrameRecord&&) {
                       if (++handed == 3) throw std::runtime_error("disk full");
                     },
                     [](const std::string&) {}),
                 std::runtime_error);
    // Nothing is handed on after the failed frame (beside the checks, the frame checked
    // meanwhile is dropped with the error).
    EXPECT_EQ(handed, 3);
  }
}

/// A scene (the drape cloth against the closed sphere, penetration measured) run both ways,
/// with and without a topology change halfway: the same records.
TEST(CheckSequence, AScenesRecordsAreTheSameRecordedBesideTheChecks) {
  // Copies of the drape frames whose last face is left out from the 6th frame on: a topology
  // change there (the vertices stay).
  const snag::test::TempDir changed;
  drape_copies(changed.path(), [](size_t i, std::string& text) {
    if (i < 5) return;
    const size_t face = text.rfind("\nf ") + 1;
    const size_t end = text.find('\n', face);
    text.erase(face, end == std::string::npos ? std::string::npos : end + 1 - face);
  });
  for (const bool change : {false, true}) {
    SCOPED_TRACE(change ? "faces change at the 6th frame" : "one topology");
    const fs::path cloth =
        (change ? changed.path() : snag::test::source_dir() / "samples" / "drape") /
        "drape.%04d.obj";
    const scene::Scene scene = scene::scene_from_flags(
        cloth.string(), {(snag::test::source_dir() / "samples" / "drape_sphere.obj").string()},
        std::nullopt);
    const scene::ResolvedScene resolved = scene::resolve_scene(scene, "");
    std::vector<std::vector<report::FrameRecord>> runs;
    for (const bool beside : {false, true}) {
      const std::unique_ptr<detect::Checker> checker = cpu_checker();
      report::Inputs inputs;
      inputs.objects.resize(resolved.objects.size());
      Handed handed;
      check_scene(
          resolved, *checker, settings_for(beside), /*scene_report=*/true, inputs,
          [&](report::FrameRecord&& r) { handed.take(std::move(r)); }, [](const std::string&) {});
      EXPECT_FALSE(handed.overlapped);
      runs.push_back(std::move(handed.records));
    }
    ASSERT_EQ(runs[0].size(), resolved.frames.size());
    ASSERT_EQ(runs[1].size(), runs[0].size());
    size_t measured = 0, changes = 0;
    for (size_t i = 0; i < runs[0].size(); ++i) {
      const report::FrameRecord &inline_record = runs[0][i], &beside = runs[1][i];
      EXPECT_EQ(beside.frame, inline_record.frame);
      EXPECT_EQ(beside.triangles, inline_record.triangles);
      EXPECT_EQ(beside.topology_changed, inline_record.topology_changed);
      EXPECT_EQ(beside.pairs, inline_record.pairs);
      EXPECT_EQ(beside.degenerate.size(), inline_record.degenerate.size());
      EXPECT_EQ(beside.penetration, inline_record.penetration);
      measured += inline_record.penetration.size();
      changes += inline_record.topology_changed;
    }
    EXPECT_GT(measured, 0u) << "the sphere is closed: the cloth is measured against it";
    EXPECT_EQ(changes, change ? 1u : 0u);
  }
}

TEST(CheckSequence, GpuRunsReadAheadWithinTheirByteBudget) {
  // The CPU, and frames of unknown size: readers + 2.
  EXPECT_EQ(frames_ahead_for(1, false, 1'000'000), 3);
  EXPECT_EQ(frames_ahead_for(15, false, 1'000'000), 17);
  EXPECT_EQ(frames_ahead_for(7, true, 0), 9);
  // A GPU: as many as the budget holds at twice their files' bytes...
  for (const uint64_t bytes : {uint64_t{100'000}, uint64_t{1'200'000}, uint64_t{5'000'000}}) {
    const int ahead = frames_ahead_for(7, true, bytes);
    EXPECT_LE(static_cast<uint64_t>(ahead) * 2 * bytes, kReadAheadBytes) << bytes;
    EXPECT_GT(static_cast<uint64_t>(ahead + 1) * 2 * bytes, kReadAheadBytes) << bytes;
  }
  // ... at least readers + 2 (large frames), at most kMostFramesAhead (tiny ones).
  EXPECT_EQ(frames_ahead_for(15, true, uint64_t{1} << 30), 17);
  EXPECT_EQ(frames_ahead_for(15, true, 100), kMostFramesAhead);
}

}  // namespace
}  // namespace snag::cli
