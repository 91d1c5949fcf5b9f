// The CUDA backend: the paper's complete BVH built, refit and traversed on the GPU, with the
// same per-node, per-leaf and per-pair functions as the CPU backend (snag/bvh, snag/geom,
// snag/detect headers), so that both give the same FilteredFrame for every input.
//
// This header has no CUDA types: the CLI and the tests include it with a plain C++ compiler.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "snag/detect/backend.h"
#include "snag/geom/box.h"
#include "snag/geom/vec3.h"

namespace snag::cuda {

/// Number of CUDA devices usable here: 0 when there is no driver, no device, or the driver is
/// too old for this build. Never throws for that.
int cuda_device_count();

/// When cuda_device_count() is 0 on a machine that has an NVIDIA driver: why, in words (a
/// driver older than this build's CUDA runtime, a GPU the driver cannot bring up, ...). Empty
/// when there are devices, and on a machine with no driver or no GPU, where using the CPU is
/// the ordinary case and needs no explanation.
std::string cuda_runtime_problem();

/// What this build's CUDA backend was compiled for, in words: its architectures
/// (SNAG_CUDA_ARCHITECTURES as CMake gave them to nvcc) and the CUDA runtime it links. Touches
/// no device.
std::string cuda_build_description();

/// Why CUDA device `device` cannot run this build's kernels, or empty when it can: a GPU older
/// than every architecture the build has code for (SNAG_CUDA_ARCHITECTURES), a device that
/// another process holds in exclusive mode, or no such device. Never throws. Makes `device`
/// the calling thread's current device and creates its context (as the backend would).
std::string cuda_device_problem(int device);

/// Device-side time of the last run of each stage, in milliseconds, from CUDA events recorded
/// on the backend's stream around the stage's kernels and copies. Stages are queued without
/// waiting where the interface allows: a checker's frame waits twice, at the end of the scan
/// and at the end of detect(), and a detect that finds the next frame staged queues that
/// frame's work before it returns.
struct StageTimes {
  double upload = 0;    ///< positions: pinned host buffer to device
  double scan = 0;      ///< degenerate-triangle scan with its result on the host; in a checker's
                        ///< frame also the refit, the quality and the detect queued ahead of
                        ///< their calls (the scan is queued after them, beside the detect).
                        ///< When the frame was staged, all of it is queued at the end of the
                        ///< previous frame's detect, and this is from then
  double build = 0;     ///< the whole GPU build, boxes and planes included
  double refit = 0;     ///< boxes and planes from the current positions (0 when refit() found
                        ///< the tree already fit to them, refit ahead in the scan or built)
  double quality = 0;   ///< tree quality, back on the host (not updated when it was ready)
  double traverse = 0;  ///< the checks' walks and their pair tests (the filtered narrow phase)
  double classify = 0;  ///< hits expanded into distinct classified pairs, sorted, on the host
};

/// The CUDA backend with what the benchmark and the tests need beyond detect::Backend.
class CudaBackend : public detect::Backend {
 public:
  /// Times of the last run of each stage (see StageTimes).
  virtual StageTimes last_times() const = 0;
  /// Keeps `frames` (each vertex_count positions) on the device, so that select_device_frame
  /// can make one of them current without crossing the bus. Replaces earlier resident frames.
  virtual void upload_resident_frames(std::span<const std::span<const geom::Vec3d>> frames) = 0;
  /// Makes resident frame `index` the current positions (no copy).
  virtual void select_resident_frame(int index) = 0;
  /// The initial capacity, in entries, of each result buffer (hits, uncertain tests, duplicated
  /// faces, pairs) and of the walks' lists (subwalks, candidate pairs). A frame that finds more
  /// grows the buffers to what it found and traverses again, so this changes speed, never
  /// results; tests set it small to exercise the growth.
  /// It also caps the pairs and uncertain tests sorted by one block (at most 8192) before the
  /// device-wide sorts take over, so small values exercise that path too.
  virtual void set_result_capacity(int64_t entries) = 0;
  /// Refit strategy: one launch in which each leaf's thread climbs while it is the second child
  /// to arrive (an atomic counter per node; the default), or one launch per level.
  virtual void set_level_by_level_refit(bool on) = 0;
  /// Records a CUDA event on the backend's stream: the start of a span timed by stop_timer().
  virtual void start_timer() = 0;
  /// Milliseconds on the backend's stream since start_timer(), host gaps included (every stage
  /// ends by waiting for its results, so this is the wall time of the calls in between).
  virtual double stop_timer() = 0;
  /// The leaf-to-triangle permutation of the current tree (copied back; for tests).
  virtual std::vector<int32_t> triangle_order() = 0;
  /// The node boxes of the current tree, breadth-first (copied back; for tests).
  virtual std::vector<geom::Box3f> node_boxes() = 0;
  /// The device's name, as the driver reports it.
  virtual std::string device_name() const = 0;
  /// How many scans and detects, since the backend was made, took the work queued for them at
  /// the end of the previous frame's detect (a frame staged while the one before it was
  /// checked), instead of queueing their own.
  struct AheadTaken {
    int64_t scans = 0;
    int64_t detects = 0;
  };
  virtual AheadTaken ahead_taken() const = 0;
  /// One kernel launch as a stream trace saw it (a build with SNAG_CUDA_TRACE, for profiling;
  /// cuda/src/trace.cuh): microseconds on the device's clock from the trace's first launch.
  struct TracedLaunch {
    int64_t threads = 0;      ///< the grid's threads, which tell the kernels apart
    double began = 0;         ///< its first block's start (before waiting for the kernel ahead)
    double passed_first = 0;  ///< its first block past that wait
    double passed_last = 0;   ///< its last block past it
  };
  /// The launches recorded on this backend's device since the last call (by any backend of the
  /// process), in start order; the first call starts the recording and returns none. None in a
  /// build without SNAG_CUDA_TRACE. Waits for the device. Every backend on a device records
  /// into the same buffer: trace one at a time.
  virtual std::vector<TracedLaunch> take_stream_trace() = 0;
};

/// Whether this build's kernels record stream traces (the CMake option SNAG_CUDA_TRACE, for
/// profiling; CudaBackend::take_stream_trace).
bool stream_trace_compiled();

/// The CUDA backend on device `device` (0-based). Throws snag::InternalError when there is no
/// such device, when it cannot run this build's kernels (cuda_device_problem), or when a CUDA
/// call fails.
std::unique_ptr<detect::Backend> make_cuda_backend(int device = 0);

}  // namespace snag::cuda
