// The frame loop of `snag check`, shared with `snag bench io` so that the benchmark times what
// users run: frames read ahead on reader threads, checked in order, each record handed on as
// soon as its frame is checked.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "snag/detect/checker.h"
#include "snag/report/report.h"
#include "snag/scene/scene_frames.h"
#include "snag/seq/sequence.h"

namespace snag::cli {

/// Where the frame loop's time went, in seconds summed over frames: on the loop's thread (the
/// checker's), and beside it on the preparing thread and, on a GPU, the recording thread.
struct LoopTimes {
  double waiting = 0;         ///< for the next frame, not yet read or compared
  double preparing = 0;       ///< a topology's set-up (weld decisions, the checker's scene, meters)
  double checking = 0;        ///< Checker::check, exact decisions included
  detect::StageTimes stages;  ///< checking by the checker's own stage clocks (FrameResult::times)
  double recording = 0;       ///< the frame's record: ids, groups, penetration (on a GPU, beside
                              ///< the loop on the recording thread, one frame behind the checks)
  double handing = 0;         ///< on_frame (the report stream takes the record; where recording is)
  double behind = 0;          ///< on a GPU, for the frame before's record and hand-over to be done
  double starting = 0;        ///< of waiting and preparing, until the first frame's check began
  double comparing = 0;       ///< on the preparing thread: vertex counts, faces and what moved,
                              ///< each frame against the one before (reading's share)
  double staging = 0;         ///< on the preparing thread: positions copied into the backend's
                              ///< staging memory (a GPU's pinned buffers; none on the CPU)
};

struct SequenceSettings {
  std::optional<double> weld;  ///< --weld: vertices closer than this count as one for adjacency
  int threads = 1;             ///< the run's threads: the checker's (checker_threads_for, with
                               ///< which its backend was made) and the readers (readers_for)
  bool gpu = false;            ///< the checker runs on a GPU (see readers_for)
  LoopTimes* times = nullptr;  ///< when given, filled with where the loop's time went
};

/// Per object: 0 when its positions in `frame` are bit for bit those in `previous` (1 for every
/// object when the two lay their objects out differently).
std::vector<uint8_t> moved_between(const scene::SceneFrame& previous,
                                   const scene::SceneFrame& frame);

/// Reader threads for a run of `threads` threads (--threads). On the CPU a frame's reading costs a
/// sixth to a twelfth of its check (36K triangles read in sequence on the H100's host: ~2 ms of one
/// CPU, against ~12 ms of checking for a frame with no pairs and 19-25 ms for one folded through
/// itself), so one reader per 8 threads (at least 1, at most 4) keeps ahead of the checker at 16
/// threads; at 8, frames with no pairs want ~1.2 readers' worth, and neither one nor two keeps up
/// with both kinds. 1,000 frames at 16 threads, two runs each (the process's wall time, 13 workers
/// and 2 readers against 14 and 1): 1.07-1.31 s against 1.97-2.17 on frames with no pairs, where
/// one reader could not keep up; 1.71-1.94 against 1.94-2.10 on folded ones. At 8 threads 2 readers
/// gained little on the first (1.74-1.99 against 1.93-2.02 s) and lost some on the second
/// (2.53-3.05 against 2.63-2.66), so one reader stays there. On a GPU reading is most of the host's
/// work: up to 8 threads every thread reads, the checker's on top (on the H100's host, 200 frames
/// of 36K triangles, snag check took 0.124-0.134 s with 3 readers at 4 threads, 0.088-0.092 with 4;
/// 0.064-0.079 with 7 at 8, 0.055-0.067 with 8). Beyond 8 threads min(threads, max(8, threads / 2))
/// read (8 from 8 to 16 threads, half beyond): readers on every CPU starve the loop's own threads
/// (the check, the comparing, the recording, the report's formatters), whose work is serial. 1,000
/// frames at 16 threads, three runs each, snag check's summary "in all" seconds: 0.68-0.86 with 16
/// readers, 0.62-0.84 with 14, 0.67-0.84 with 12, 0.50-0.77 with 8 on frames folded through
/// themselves; 0.62-0.71, 0.42-0.60, 0.43-0.60 and 0.49-0.51 on frames with no pairs. Readers wait
/// whenever the frames ahead fill their ring (frames_ahead_for).
int readers_for(int threads, bool gpu);

/// Frames the readers may hold ahead of the loop (read, or being read, not yet taken), for
/// frames whose files take `frame_file_bytes` (every object's file of the first frame). On the
/// CPU readers + 2: the check is the slower side, and frames read further ahead would only wait.
/// On a GPU as many as kReadAheadBytes holds (kMostFramesAhead at most) at twice their files' bytes
/// (a parsed frame takes about as much memory as its OBJ text, half again a binary PLY's), at least
/// readers + 2: the loop's start (the first frame parsed in full, its topology, the tree) takes ~25
/// ms at 36K triangles on the H100's host, and readers that stopped after readers + 2 frames then
/// sat idle while a GPU check keeps up with them afterwards.
int frames_ahead_for(int readers, bool gpu, uint64_t frame_file_bytes);
constexpr uint64_t kReadAheadBytes = uint64_t{256} << 20;
constexpr int kMostFramesAhead = 4096;  ///< however small the frames

/// The checker's worker threads in a run of `threads`. On the CPU with 8 threads or more, the
/// readers' threads are taken out, so that the run stays within `threads`: OpenMP's workers spin
/// between parallel regions, and readers that took their cores stalled the regions and were starved
/// in turn. 16 logical CPUs of the H100 host, 200 frames of 36K triangles, snag check against
/// checking alone on 16 threads at 7505b01: 2.05 times with 16 workers and a reader on top, 1.45
/// with 12 workers and 4 readers, 1.26 with 14 and 2, 1.21 with 15 and 1 (whose loop checked as
/// fast as the check alone: checks were slower then, and one reader kept up with them; now two do,
/// see readers_for). So now 16 threads give 13 workers, 2 readers and 1 left over; 8 give 7 and 1.
/// From 16 threads one more CPU in 16 is left to the preparing thread and the report stream's
/// formatters, whose frames otherwise waited for a core while the workers spun: snag check
/// 0.49-0.58 s with 15 workers, 0.41-0.52 with 14, four runs each (the same host, checking alone
/// 0.27-0.43; with 14 the loop's wait to hand a frame to the report stream 0.001-0.06 s where it
/// was 0.09-0.10). Below 8 threads, where a reader's CPU would be a seventh to a half of the
/// check's, and on a GPU, whose checker uses its CPU threads only for the exact stage, the readers
/// come on top and the checker has all `threads`.
int checker_threads_for(int threads, bool gpu);

/// Reads `frames` ahead and checks them in order with `checker`:
///  - the topology comes from the first frame; later frames must have its vertex count, and a
///    different face list is a topology change (a new tree, record.topology_changed);
///  - with a weld, each topology's first frame decides which vertices count as one;
///  - each frame is compared with the one before on a thread of its own, ahead of its check;
///  - on a GPU, each next frame is staged while the current one is checked.
/// Each frame's record goes to `on_frame`, in order, as soon as it is checked: on a GPU from a
/// recording thread while the next frame is checked, else from the calling thread (on_frame is
/// never called from two threads at once, and `warn` never while on_frame runs); `warn` gets
/// warnings (a first frame with coincident vertices and no weld). Fills inputs.ids,
/// coincident_vertices and welded_vertices. Throws snag::InputError for a bad frame at its turn,
/// after every frame before it was handed on.
void check_sequence(std::span<const seq::Frame> frames, detect::Checker& checker,
                    const SequenceSettings& settings, report::Inputs& inputs,
                    const std::function<void(report::FrameRecord&&)>& on_frame,
                    const std::function<void(const std::string&)>& warn);

/// The same loop over a scene's objects, each frame one mesh of every object laid end to end
/// (scene::SceneReader), one tree per object:
///  - an object whose positions are bit for bit its previous frame's is not refit, and checks
///    between such objects keep their pairs (reported as reused); a still object is read,
///    built and (on a GPU) uploaded once;
///  - each object is welded with its own tolerance, and pairs its ignore rules name are left
///    out;
///  - cloth vertices inside each closed obstacle they are checked against are measured
///    (report::Penetration); an obstacle that is not closed is named in inputs.objects.
/// With `scene_report` the records and inputs.objects describe every object (a scene run);
/// without, the scene must be one object and the records are a single mesh's.
void check_scene(const scene::ResolvedScene& scene, detect::Checker& checker,
                 const SequenceSettings& settings, bool scene_report, report::Inputs& inputs,
                 const std::function<void(report::FrameRecord&&)>& on_frame,
                 const std::function<void(const std::string&)>& warn);

}  // namespace snag::cli
