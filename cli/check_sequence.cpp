#include "check_sequence.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "snag/error.h"
#include "snag/measure/penetration.h"
#include "snag/mesh/weld.h"
#include "snag/seq/prefetch.h"

namespace snag::cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A Tri is three int32 ids and nothing else, so equal faces are equal bytes: one memcmp
/// (the loop's per-frame topology test, 45 -> 39 us for 36K triangles on the 2-core EPYC).
static_assert(sizeof(geom::Tri) == 3 * sizeof(int32_t) &&
              std::has_unique_object_representations_v<geom::Tri>);
bool same_faces(const std::vector<geom::Tri>& a, const std::vector<geom::Tri>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(geom::Tri)) == 0);
}

using ScenePrefetcher = seq::Prefetcher<scene::SceneFrame>;

/// A frame read ahead and compared with the frame before it on the preparing thread, waiting
/// there for its turn on the checker's.
struct PreparedFrame {
  /// Shared with the preparing thread, which compares the next frame with it.
  std::shared_ptr<const ScenePrefetcher::Prefetched> frame;
  bool topology_changed = false;  ///< its faces (or objects' triangle counts) differ from the
                                  ///< frame before's
  /// Per object, 0 when its positions are bit for bit the frame before's (moved_between);
  /// empty for the first frame.
  std::vector<uint8_t> moved;
  double comparing_seconds = 0;  ///< the preparing thread's time on it (reading's share)
  /// Its positions copied into the backend's staging memory (a GPU's pinned buffers), when the
  /// backend has such memory and a buffer was free; the check then passes this span, which the
  /// backend transfers without a copy of its own on the checker's thread.
  std::shared_ptr<const detect::StagedPositions> staged;
  double staging_seconds = 0;  ///< the preparing thread's time copying it there
  std::exception_ptr error;    ///< reading or comparing it failed: thrown at its turn

  /// The positions to check: the staged copy, else the mesh's own.
  std::span<const geom::Vec3d> positions() const {
    return staged ? staged->positions() : std::span<const geom::Vec3d>(frame->item.mesh.positions);
  }
};

/// Frames in order from the preparing thread to the checker's, at most `capacity` waiting, so
/// that memory stays bounded whatever the sequence length.
class FrameHandoff {
 public:
  explicit FrameHandoff(size_t capacity) : capacity_(std::max<size_t>(capacity, 1)) {}

  /// Preparing thread: adds the next frame once there is room. False when the checker's thread
  /// takes no more (it stopped: the run failed, or is over).
  bool put(PreparedFrame&& frame) {
    std::unique_lock lock(mutex_);
    room_.wait(lock, [&] { return stopped_ || waiting_.size() < capacity_; });
    if (stopped_) return false;
    waiting_.push_back(std::move(frame));
    lock.unlock();
    ready_.notify_one();
    return true;
  }
  /// Preparing thread: no frame comes after those put; with `error`, the next frame's turn
  /// throws it (kept aside: nothing to allocate while failing).
  void close(std::exception_ptr error = nullptr) {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
      error_ = std::move(error);
    }
    ready_.notify_one();
  }
  /// Checker's thread: the next frame, once prepared; nullopt after the last.
  std::optional<PreparedFrame> take() {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return closed_ || !waiting_.empty(); });
    return pop(lock);
  }
  /// Checker's thread: the next frame if it is prepared already, else nullopt.
  std::optional<PreparedFrame> take_if_ready() {
    std::unique_lock lock(mutex_);
    return pop(lock);
  }
  /// Checker's thread: no more frames are wanted; a put() waiting for room returns false.
  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopped_ = true;
    }
    room_.notify_all();
  }

 private:
  std::optional<PreparedFrame> pop(std::unique_lock<std::mutex>& lock) {
    if (waiting_.empty()) {
      if (!error_) return std::nullopt;
      PreparedFrame failed;
      failed.error = std::exchange(error_, nullptr);
      return failed;
    }
    PreparedFrame frame = std::move(waiting_.front());
    waiting_.pop_front();
    lock.unlock();
    room_.notify_one();
    return frame;
  }

  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable room_, ready_;
  std::deque<PreparedFrame> waiting_;
  std::exception_ptr error_;  ///< the preparing thread's, after the frames waiting
  bool closed_ = false, stopped_ = false;
};

/// The preparing thread: takes each frame in order from the readers, checks its objects'
/// vertex counts against the first frame's and compares its faces and positions with the frame
/// before's, stages its positions (when `staging` is given), and puts it into `handoff`. A
/// failure (a bad file, a vertex count that changed, or anything thrown here) closes the handoff
/// with it, to be thrown at that frame's turn.
void prepare_frames(ScenePrefetcher& prefetcher, const scene::ResolvedScene& scene,
                    bool scene_report, detect::HostStaging* staging, FrameHandoff& handoff) {
  try {
    std::shared_ptr<const ScenePrefetcher::Prefetched> previous;
    std::vector<int32_t> first_vertices;  // per object, the first frame's vertex count
    std::vector<std::string> first_files;
    for (;;) {
      std::optional<ScenePrefetcher::Prefetched> next = prefetcher.next();
      if (!next) break;
      const auto started = Clock::now();
      PreparedFrame prepared;
      auto frame = std::make_shared<const ScenePrefetcher::Prefetched>(std::move(*next));
      const scene::SceneFrame& scene_frame = frame->item;
      const detect::PartLayout& layout = scene_frame.layout;
      const auto object_count = static_cast<int32_t>(layout.vertex_begin.size()) - 1;
      for (int32_t o = 0; o < object_count; ++o) {
        const int32_t vertices = layout.vertex_begin[o + 1] - layout.vertex_begin[o];
        if (!previous) {
          first_vertices.push_back(vertices);
          first_files.push_back(scene_frame.files[o]);
        } else if (vertices != first_vertices[o]) {
          throw InputError(scene_frame.files[o], 0,
                           "has " + std::to_string(vertices) + " vertices" +
                               (scene_report ? " in object \"" + scene.objects[o].spec.name + "\""
                                             : std::string()) +
                               ", but the first frame (" + first_files[o] + ") has " +
                               std::to_string(first_vertices[o]) +
                               "; every frame of a sequence must have the same vertices");
        }
      }
      // The frame before had the topology's faces, or started a topology of its own.
      if (previous) {
        const scene::SceneFrame& before = previous->item;
        prepared.topology_changed =
            !same_faces(scene_frame.mesh.triangles, before.mesh.triangles) ||
            layout.triangle_begin != before.layout.triangle_begin;
        prepared.moved = moved_between(before, scene_frame);
      }
      prepared.frame = frame;
      prepared.comparing_seconds = seconds_since(started);
      if (staging) {
        const auto staging_started = Clock::now();
        prepared.staged = staging->stage(scene_frame.mesh.positions);
        prepared.staging_seconds = seconds_since(staging_started);
      }
      previous = std::move(frame);
      if (!handoff.put(std::move(prepared))) return;  // the checker's thread stopped
    }
    handoff.close();
  } catch (...) {
    handoff.close(std::current_exception());
  }
}

/// The preparing thread of one run, joined on every way out of it, errors included: the
/// checker's thread stops taking frames first, so that it is not left waiting for room.
class PreparingThread {
 public:
  PreparingThread(FrameHandoff& handoff, std::function<void()> body)
      : handoff_(handoff), thread_(std::move(body)) {}
  ~PreparingThread() {
    handoff_.stop();
    thread_.join();
  }
  PreparingThread(const PreparingThread&) = delete;
  PreparingThread& operator=(const PreparingThread&) = delete;

 private:
  FrameHandoff& handoff_;
  std::thread thread_;
};

/// A cloth measured against a meter, with what earlier frames proved about its vertices.
struct MeasuredCloth {
  int32_t object = 0;
  measure::Clearance clearance;
};

/// A checked frame on its way to its record: the frame (its mesh, files and what moved), the
/// checker's result, and its reading time.
struct CheckedFrame {
  PreparedFrame prepared;
  detect::FrameResult result;
  double read_seconds = 0;
};

/// Makes each checked frame's record and hands it on (`record`), in order. On a GPU it does so
/// on a thread of its own, one frame behind the checks: the checks mostly wait for the device,
/// and the record (pair ids, groups, penetration) and its hand-over to the report stream,
/// ~75 us a frame at 36K triangles on the H100's host, then overlap the next frame's check
/// instead of following it. At most one frame is recorded while the next is checked (add()
/// waits for the one before). On the CPU the record is made in add() itself: there the check's
/// workers have every core, and a penetration meter's OpenMP loops beside theirs would compete.
///
/// A record reads its frame, its result, and the penetration meters the loop's thread set up for
/// the frame's topology: the loop calls finish() before it changes them (at a topology's first
/// frame), so that a record never meets the next topology's meters.
class FrameRecorder {
 public:
  FrameRecorder(bool beside, std::function<void(CheckedFrame&&)> record)
      : record_(std::move(record)) {
    if (beside) thread_ = std::thread([this] { run(); });
  }
  ~FrameRecorder() {
    if (!beside()) return;
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  /// Records `frame` once the frame before is recorded; rethrows that frame's error.
  void add(CheckedFrame&& frame) {
    if (!beside()) {
      record_(std::move(frame));
      return;
    }
    std::unique_lock lock(wait_until_idle());
    pending_ = std::move(frame);
    lock.unlock();
    changed_.notify_all();
  }
  /// Whether frames are recorded on a thread of their own.
  bool beside() const { return thread_.joinable(); }
  /// Waits until every frame added is recorded; rethrows a recording's error.
  void finish() {
    if (beside()) wait_until_idle();
  }

 private:
  std::unique_lock<std::mutex> wait_until_idle() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !pending_ && !busy_; });
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return lock;
  }
  void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return stopping_ || pending_; });
      if (stopping_) return;  // a frame not yet taken is dropped: the run failed
      CheckedFrame frame = std::move(*pending_);
      pending_.reset();
      busy_ = true;
      lock.unlock();
      std::exception_ptr error;
      try {
        record_(std::move(frame));
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      busy_ = false;
      if (error && !error_) error_ = std::move(error);
      changed_.notify_all();
    }
  }

  std::function<void(CheckedFrame&&)> record_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<CheckedFrame> pending_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest is made
};

/// A closed obstacle's meter, and the cloths it is measured against.
struct Meter {
  int32_t obstacle = 0;
  std::unique_ptr<measure::PenetrationMeter> meter;
  std::vector<MeasuredCloth> cloths;
  bool fresh = true;  ///< made this frame, with its positions
};

/// One object's part of the scene's (welded) triangles, its own vertex ids from 0.
std::vector<geom::Tri> local_triangles(std::span<const geom::Tri> triangles,
                                       const detect::PartLayout& layout, int32_t object) {
  const int32_t base = layout.vertex_begin[object];
  std::vector<geom::Tri> local(triangles.begin() + layout.triangle_begin[object],
                               triangles.begin() + layout.triangle_begin[object + 1]);
  for (geom::Tri& t : local)
    for (int k = 0; k < 3; ++k) t.v[k] -= base;
  return local;
}

/// Why an obstacle is not closed, in the ids of its file: its triangles as the file numbers
/// their vertices (an object of one group uses some of them), and, for a group, a word on
/// how its triangles are counted.
std::optional<std::string> why_obstacle_not_closed(const scene::SceneFrame& frame,
                                                   std::span<const geom::Tri> local, int32_t object,
                                                   bool group) {
  const int32_t base = frame.layout.vertex_begin[object];
  const int32_t vertices = frame.layout.vertex_begin[object + 1] - base;
  if (frame.file_vertex.empty()) return measure::why_not_closed(local, vertices);
  std::vector<geom::Tri> in_file(local.begin(), local.end());
  int32_t file_vertices = 0;
  for (geom::Tri& t : in_file)
    for (int k = 0; k < 3; ++k) {
      t.v[k] = frame.file_vertex[base + t.v[k]];
      file_vertices = std::max(file_vertices, t.v[k] + 1);
    }
  std::optional<std::string> why = measure::why_not_closed(in_file, file_vertices);
  if (why && group) *why += " (vertex ids are the file's; triangles are counted within the group)";
  return why;
}

template <class T>
std::span<const T> slice(const std::vector<T>& all, const std::vector<int32_t>& begin,
                         int32_t object) {
  return std::span<const T>(all).subspan(static_cast<size_t>(begin[object]),
                                         static_cast<size_t>(begin[object + 1] - begin[object]));
}

/// The vertex each vertex of a topology's first frame counts as for adjacency
/// (mesh::welded_triangles), per object with its own --weld tolerance; empty when no vertex is
/// welded to another. On the sequence's first frame (`first`) it counts the welded vertices
/// into `inputs` and warns of exactly coincident vertices in objects that weld nothing.
std::vector<int32_t> adjacency_representatives(
    const scene::ResolvedScene& scene, const scene::SceneFrame& frame, bool first,
    report::Inputs& inputs, const std::function<void(const std::string&)>& warn) {
  const detect::PartLayout& layout = frame.layout;
  std::vector<int32_t> representative;
  int64_t welded_in_all = 0;
  for (int32_t o = 0; o < static_cast<int32_t>(scene.objects.size()); ++o) {
    const std::span<const geom::Vec3d> positions =
        slice(frame.mesh.positions, layout.vertex_begin, o);
    const std::optional<double>& weld = scene.objects[o].spec.weld;
    if (weld) {
      const std::vector<int32_t> local = mesh::weld_representatives(positions, *weld);
      int64_t welded = 0;
      for (size_t v = 0; v < local.size(); ++v) {
        welded += local[v] != static_cast<int32_t>(v);
        representative.push_back(local[v] + layout.vertex_begin[o]);
      }
      welded_in_all += welded;
      if (first) inputs.welded_vertices += welded;
      continue;
    }
    for (int32_t v = layout.vertex_begin[o]; v < layout.vertex_begin[o + 1]; ++v)
      representative.push_back(v);
    if (!first) continue;
    const int64_t coincident = mesh::count_coincident_vertices(positions);
    inputs.coincident_vertices += coincident;
    if (coincident > 0)
      warn(frame.files[o] + ": " + std::to_string(coincident) +
           (coincident == 1 ? " vertex coincides" : " vertices coincide") +
           " exactly with another vertex but are separate vertices; unwelded seams are "
           "reported as intersections (use --weld TOL)");
  }
  if (welded_in_all == 0) representative.clear();
  return representative;
}

/// A topology's penetration meters: one per closed obstacle that a cloth is checked against,
/// with those cloths, over the frame's positions. Closedness is the weld's (`welded`: the
/// scene's triangles after mesh::welded_triangles), and an obstacle whose faces point inwards
/// is measured flipped. With `record_closed` (a scene report's first frame), each such
/// obstacle's closedness goes into `inputs`.
std::vector<Meter> make_meters(const scene::ResolvedScene& scene, const scene::SceneFrame& frame,
                               std::span<const geom::Tri> welded, bool record_closed,
                               report::Inputs& inputs, int workers) {
  const detect::PartLayout& layout = frame.layout;
  std::vector<Meter> meters;
  for (const detect::PartCheck& c : scene.checks) {
    if (c.self()) continue;
    const auto role = [&](int32_t o) { return scene.objects[o].spec.role; };
    if (role(c.a) == role(c.b)) continue;
    const int32_t obstacle = role(c.a) == scene::Role::obstacle ? c.a : c.b;
    const int32_t cloth = obstacle == c.a ? c.b : c.a;
    auto at = std::find_if(meters.begin(), meters.end(),
                           [&](const Meter& m) { return m.obstacle == obstacle; });
    if (at == meters.end()) {
      // Closedness as the weld sees it: a body stored as a triangle soup can be welded.
      const std::vector<geom::Tri> local = local_triangles(welded, layout, obstacle);
      const int32_t vertices = layout.vertex_begin[obstacle + 1] - layout.vertex_begin[obstacle];
      const std::optional<std::string> why = why_obstacle_not_closed(
          frame, local, obstacle, scene.objects[obstacle].spec.group.has_value());
      if (record_closed)
        inputs.objects[static_cast<size_t>(obstacle)].closed = why ? *why : "closed";
      if (why) continue;
      // A closed obstacle whose faces point inwards would measure its complement: its inside is
      // the side of negative enclosed volume, so it is measured flipped.
      const std::span<const geom::Vec3d> positions =
          slice(frame.mesh.positions, layout.vertex_begin, obstacle);
      auto meter = std::make_unique<measure::PenetrationMeter>(local, vertices);
      meter->update_positions(positions, workers);
      if (meter->enclosed_volume() < 0) {
        std::vector<geom::Tri> flipped = local;
        for (geom::Tri& t : flipped) std::swap(t.v[1], t.v[2]);
        meter = std::make_unique<measure::PenetrationMeter>(flipped, vertices);
        meter->update_positions(positions, workers);
      }
      meters.push_back({obstacle, std::move(meter), {}, true});
      at = meters.end() - 1;
    }
    at->cloths.push_back({cloth, {}});
  }
  return meters;
}

/// Whether an ignore rule of either object leaves the pair of (group a, group b) out.
bool ignored(const scene::ResolvedScene& scene, int32_t object_a, const std::string& group_a,
             int32_t object_b, const std::string& group_b) {
  auto matches = [](const std::string& rule, const std::string& group) {
    return rule == "*" || rule == group;
  };
  for (const auto& [owner, other] :
       {std::pair{object_a, object_b}, std::pair{object_b, object_a}}) {
    const std::string& mine = owner == object_a ? group_a : group_b;
    const std::string& theirs = owner == object_a ? group_b : group_a;
    for (const scene::IgnoreRule& rule : scene.objects[owner].spec.ignore)
      if ((matches(rule.a, mine) && matches(rule.b, theirs)) ||
          (owner == other && matches(rule.b, mine) && matches(rule.a, theirs)))
        return true;
  }
  return false;
}

}  // namespace

std::vector<uint8_t> moved_between(const scene::SceneFrame& previous,
                                   const scene::SceneFrame& frame) {
  const auto& begin = frame.layout.vertex_begin;
  std::vector<uint8_t> moved(begin.size() - 1, 1);
  if (previous.layout.vertex_begin != begin) return moved;
  for (size_t p = 0; p + 1 < begin.size(); ++p)
    moved[p] = std::memcmp(previous.mesh.positions.data() + begin[p],
                           frame.mesh.positions.data() + begin[p],
                           static_cast<size_t>(begin[p + 1] - begin[p]) * sizeof(geom::Vec3d)) != 0;
  return moved;
}

int readers_for(int threads, bool gpu) {
  threads = std::max(threads, 1);
  return gpu ? std::min(threads, std::max(8, threads / 2)) : std::clamp(threads / 8, 1, 4);
}

int frames_ahead_for(int readers, bool gpu, uint64_t frame_file_bytes) {
  const int least = std::max(readers, 1) + 2;
  if (!gpu || frame_file_bytes == 0) return least;
  const uint64_t frames = kReadAheadBytes / (2 * frame_file_bytes);
  return static_cast<int>(std::clamp<uint64_t>(frames, static_cast<uint64_t>(least),
                                               std::max(kMostFramesAhead, least)));
}

int checker_threads_for(int threads, bool gpu) {
  threads = std::max(threads, 1);
  if (gpu || threads < 8) return threads;
  return threads - readers_for(threads, gpu) - threads / 16;
}

void check_sequence(std::span<const seq::Frame> frames, detect::Checker& checker,
                    const SequenceSettings& settings, report::Inputs& inputs,
                    const std::function<void(report::FrameRecord&&)>& on_frame,
                    const std::function<void(const std::string&)>& warn) {
  scene::ResolvedScene scene;
  scene::ResolvedObject object;
  object.spec.name = "cloth";
  object.spec.weld = settings.weld;
  object.frames.assign(frames.begin(), frames.end());
  scene.objects.push_back(std::move(object));
  scene.frames.assign(frames.begin(), frames.end());
  scene.checks = {detect::PartCheck{0, 0}};
  check_scene(scene, checker, settings, false, inputs, on_frame, warn);
}

void check_scene(const scene::ResolvedScene& scene, detect::Checker& checker,
                 const SequenceSettings& settings, bool scene_report, report::Inputs& inputs,
                 const std::function<void(report::FrameRecord&&)>& on_frame,
                 const std::function<void(const std::string&)>& warn) {
  const auto object_count = static_cast<int32_t>(scene.objects.size());
  if (!scene_report && object_count != 1)
    throw InternalError("check_scene: a single-mesh report of " + std::to_string(object_count) +
                        " objects");
  std::vector<Meter> meters;
  bool any_assimp = false;
  // Group names are compared per reported pair only when some object has ignore rules.
  const bool any_ignore_rules =
      std::any_of(scene.objects.begin(), scene.objects.end(),
                  [](const scene::ResolvedObject& o) { return !o.spec.ignore.empty(); });
  // A scene report's check of each (object, object): its index in the frame's checks, or -1.
  std::vector<int32_t> check_of;
  // A run of this checker cut short by an error may have left its next frame staged, in memory
  // given back since (a staging buffer, a frame's vector) that this run's frames may reuse.
  checker.forget_next_frame();

  // Frames are read ahead on their own threads, each with its own FrameReaders (which parse
  // only positions while the faces stay those of their previous frame), while the current one
  // is checked: at most `ahead` frames being read or waiting for the preparing thread,
  // kPrepared waiting for this one, the preparing thread's previous and its current, this
  // thread's current and following, and on a GPU the frame before being recorded, whatever the
  // sequence length.
  const scene::SceneReader reader(scene);
  const int readers = readers_for(settings.threads, settings.gpu);
  const int workers = checker_threads_for(settings.threads, settings.gpu);
  std::vector<std::vector<io::FrameReader>> per_reader;
  for (int r = 0; r < readers; ++r) per_reader.push_back(reader.make_readers());
  // The first frame's files: what a frame's memory is estimated from. A still object is read
  // once, but every frame read holds a copy of it (SceneReader lays the objects end to end).
  uint64_t frame_file_bytes = 0;
  for (const scene::ResolvedObject& object : scene.objects) {
    if (object.frames.empty()) continue;
    std::error_code unknown;  // then counted as nothing: the least read-ahead
    const uintmax_t bytes = std::filesystem::file_size(object.frames[0].path, unknown);
    if (!unknown) frame_file_bytes += bytes;
  }
  const int ahead = std::min(frames_ahead_for(readers, settings.gpu, frame_file_bytes),
                             std::max(static_cast<int>(scene.frames.size()), readers + 2));
  ScenePrefetcher prefetcher(scene.frames, readers, ahead, [&](const seq::Frame& f, int r) {
    // Frame numbers are unique and increasing.
    const auto index =
        static_cast<size_t>(std::lower_bound(scene.frames.begin(), scene.frames.end(), f,
                                             [](const seq::Frame& x, const seq::Frame& y) {
                                               return x.number < y.number;
                                             }) -
                            scene.frames.begin());
    return reader.read(index, per_reader[static_cast<size_t>(r)]);
  });
  // Each frame is compared with the one before it (vertex counts, faces, what moved) on a
  // preparing thread of its own, a frame or two ahead of this thread, which checks them in
  // order: on a GPU the checks mostly wait for the device, and the comparisons (~35 us a frame
  // at 36K triangles on the H100's host) and the wait for the readers now happen meanwhile
  // (the GPU loop 0.088-0.102 -> 0.062-0.076 s over 200 frames). At most kPrepared frames
  // wait between the two.
  constexpr size_t kPrepared = 2;
  FrameHandoff handoff(kPrepared);
  // Frames prepared and not yet recorded hold a staging buffer each: kPrepared waiting, the
  // preparing thread's current, this thread's current and following, and the recording
  // thread's; one more for a frame between two of these. A frame that finds none free is
  // transferred as any other.
  const std::shared_ptr<detect::HostStaging> staging =
      checker.host_staging(static_cast<int>(kPrepared) + 5);
  const PreparingThread preparing(
      handoff, [&] { prepare_frames(prefetcher, scene, scene_report, staging.get(), handoff); });
  LoopTimes times;
  auto mark = Clock::now();
  // Adds the time since the last mark to `slot`.
  const auto lap = [&](double& slot) {
    const auto now = Clock::now();
    slot += std::chrono::duration<double>(now - mark).count();
    mark = now;
  };
  // A checked frame's record, handed on (on a GPU beside this thread: FrameRecorder).
  std::vector<report::Penetration> last_penetration;
  const auto record_frame = [&](CheckedFrame&& checked) {
    const auto started = Clock::now();
    const size_t i = checked.prepared.frame->index;
    const seq::Frame& frame = scene.frames[i];
    const scene::SceneFrame& scene_frame = checked.prepared.frame->item;
    const mesh::Mesh& mesh = scene_frame.mesh;
    const detect::PartLayout& layout = scene_frame.layout;
    const detect::FrameResult& result = checked.result;
    report::FrameRecord record;
    if (!scene_report) {
      record = report::make_frame_record(
          frame.number, frame.path.string(), result, mesh.source_polygon,
          static_cast<int32_t>(mesh.positions.size()), scene_frame.polygons.front());
    } else {
      record.frame = frame.number;
      record.file = scene_frame.files.front();
      record.vertices = static_cast<int32_t>(mesh.positions.size());
      record.triangles = static_cast<int32_t>(mesh.triangles.size());
      for (int64_t p : scene_frame.polygons) record.polygons += p;
      report::copy_check_counts(result, record);
      // A scene of one whole mesh has the file's ids (no table).
      const auto file_id = [&](int32_t t) {
        return scene_frame.file_triangle.empty() ? t : scene_frame.file_triangle[t];
      };
      const auto group_name = [&](int32_t t) {
        const int32_t g = mesh.triangle_group.empty() ? -1 : mesh.triangle_group[t];
        return g < 0 ? std::string("default") : mesh.group_names[g];
      };
      std::vector<report::CheckFrame> checks;
      check_of.assign(static_cast<size_t>(object_count) * static_cast<size_t>(object_count), -1);
      for (const detect::CheckOutcome& c : result.checks) {
        check_of[static_cast<size_t>(c.part_a) * object_count + c.part_b] =
            static_cast<int32_t>(checks.size());
        checks.push_back({c.part_a, c.part_b, 0, c.reused, c.seconds});
      }
      for (const detect::FacePair& p : result.pairs) {
        const int32_t oa = layout.part_of(p.a), ob = layout.part_of(p.b);
        if (any_ignore_rules && ignored(scene, oa, group_name(p.a), ob, group_name(p.b))) continue;
        record.pairs.push_back({file_id(p.a), file_id(p.b), p.kind, mesh.source_polygon[p.a],
                                mesh.source_polygon[p.b], oa, ob});
        if (const int32_t c = check_of[static_cast<size_t>(oa) * object_count + ob]; c >= 0)
          ++checks[c].pairs;
      }
      std::sort(record.pairs.begin(), record.pairs.end(), report::pair_order);
      for (int32_t t : result.degenerate)
        record.degenerate.push_back({file_id(t), mesh.source_polygon[t], layout.part_of(t)});
      record.checks = std::move(checks);
      for (int32_t o = 0; o < object_count; ++o) {
        const detect::PartOutcome& part = result.parts[o];
        record.objects.push_back({scene_frame.files[o], part.moved != 0, part.rebuilt,
                                  part.build_seconds, part.refit_seconds, part.tree_quality,
                                  layout.triangle_begin[o + 1] - layout.triangle_begin[o]});
      }
      // Penetration: measured again only when the cloth or the obstacle moved.
      std::vector<report::Penetration> penetration;
      for (Meter& m : meters) {
        const bool obstacle_moved = result.parts[m.obstacle].moved;
        if (obstacle_moved && !m.fresh)  // a fresh meter has this frame's positions
          m.meter->update_positions(slice(mesh.positions, layout.vertex_begin, m.obstacle),
                                    workers);
        for (MeasuredCloth& measured : m.cloths) {
          const int32_t cloth = measured.object;
          const auto kept = std::find_if(last_penetration.begin(), last_penetration.end(),
                                         [&](const report::Penetration& p) {
                                           return p.cloth == cloth && p.obstacle == m.obstacle;
                                         });
          if (!obstacle_moved && !result.parts[cloth].moved && kept != last_penetration.end()) {
            penetration.push_back(*kept);
            continue;
          }
          const measure::PenetrationStats stats = m.meter->measure(
              slice(mesh.positions, layout.vertex_begin, cloth), measured.clearance, workers);
          penetration.push_back({cloth, m.obstacle, stats.points, stats.inside, stats.ratio,
                                 stats.max_depth, stats.mean_depth, stats.p95_depth});
        }
        m.fresh = false;
      }
      std::sort(penetration.begin(), penetration.end(),
                [](const report::Penetration& x, const report::Penetration& y) {
                  return x.cloth != y.cloth ? x.cloth < y.cloth : x.obstacle < y.obstacle;
                });
      last_penetration = penetration;
      record.penetration = std::move(penetration);
    }
    record.topology_changed = checked.prepared.topology_changed;
    record.read_seconds = checked.read_seconds;
    const auto made = Clock::now();
    times.recording += std::chrono::duration<double>(made - started).count();
    on_frame(std::move(record));
    times.handing += seconds_since(made);
  };
  FrameRecorder recorder(settings.gpu, record_frame);
  // The loop's waits for records made beside it; where they are made in add(), their time is
  // recording and handing, and nothing more is counted.
  double not_counted = 0;
  double& behind = recorder.beside() ? times.behind : not_counted;
  std::optional<PreparedFrame> current = handoff.take();
  lap(times.waiting);
  // A frame's error (or the checker's) is thrown once the frames before it are handed on.
  try {
    while (current) {
      if (current->error) std::rethrow_exception(current->error);
      // The frame after this one: a GPU copies its positions across and queues its checks
      // while this one is checked. On a GPU it is waited for: when the preparing thread runs at
      // about the checker's pace (frames with no pairs), a frame not quite ready would
      // otherwise be checked with nothing queued behind it, and the next one's upload and
      // launches would all come after. The CPU queues nothing ahead, so it takes the frame only
      // when it is there. A frame that failed waits for its turn.
      std::optional<PreparedFrame> following =
          settings.gpu ? handoff.take() : handoff.take_if_ready();
      lap(times.waiting);

      const size_t i = current->frame->index;
      if (i == 0 || current->topology_changed) {
        // The frames before are recorded with the meters set up for their topology.
        recorder.finish();
        lap(behind);
      }
      const auto read_started = Clock::now();  // welding counts as reading
      const scene::SceneFrame& scene_frame = current->frame->item;
      const mesh::Mesh& mesh = scene_frame.mesh;
      const detect::PartLayout& layout = scene_frame.layout;
      any_assimp = any_assimp || scene_frame.any_assimp;
      const bool topology_changed = current->topology_changed;
      if (i == 0 && scene_report)
        for (int32_t o = 0; o < object_count; ++o) {
          report::ObjectInput& input = inputs.objects.at(static_cast<size_t>(o));
          input.vertices = layout.vertex_begin[o + 1] - layout.vertex_begin[o];
          input.triangles = layout.triangle_begin[o + 1] - layout.triangle_begin[o];
        }

      if (i == 0 || topology_changed) {
        // An empty file checks clean, which a gate should not pass in silence (a cache cut
        // short, a zero-byte export).
        for (int32_t o = 0; o < object_count; ++o)
          if (layout.triangle_begin[o + 1] == layout.triangle_begin[o])
            warn(scene_frame.files[o] + ": no triangles (" +
                 std::to_string(layout.vertex_begin[o + 1] - layout.vertex_begin[o]) +
                 " vertices); nothing of it is checked");
        // Welding is decided once per topology, on its first frame, per object with its own
        // tolerance: seams stay closed while the cloth moves, and a weld that changed from
        // frame to frame would rebuild the tree.
        const std::vector<geom::Tri> welded = mesh::welded_triangles(
            mesh.triangles, adjacency_representatives(scene, scene_frame, i == 0, inputs, warn));
        checker.set_scene(welded, static_cast<int32_t>(mesh.positions.size()), layout,
                          scene.checks);
        meters = make_meters(scene, scene_frame, welded, i == 0 && scene_report, inputs, workers);
      }
      const double read_seconds =
          current->frame->read_seconds + current->comparing_seconds + seconds_since(read_started);
      times.comparing += current->comparing_seconds;
      times.staging += current->staging_seconds;

      // What moved since the frame before (not asked for a topology's first frame), and the next
      // frame's positions and what moved in them since this one.
      std::span<const uint8_t> moved;
      if (!topology_changed) moved = current->moved;
      std::span<const geom::Vec3d> next_positions;
      std::span<const uint8_t> next_moved;
      if (following && following->frame) {
        next_positions = following->positions();
        next_moved = following->moved;
      }
      lap(times.preparing);
      if (i == 0) times.starting = times.waiting + times.preparing;
      // Read by snag's readers, which reject non-finite coordinates.
      detect::FrameResult result =
          checker.check({current->positions(), moved, next_positions, next_moved, /*finite=*/true});
      lap(times.checking);
      times.stages += result.times;
      recorder.add({std::move(*current), std::move(result), read_seconds});
      lap(behind);

      current = following ? std::move(following) : handoff.take();
      lap(times.waiting);
    }
    recorder.finish();
  } catch (...) {
    std::exception_ptr error = std::current_exception();
    try {
      recorder.finish();
    } catch (...) {
      error = std::current_exception();  // an earlier frame's: its failure came first
    }
    std::rethrow_exception(error);
  }
  lap(behind);
  if (settings.times) *settings.times = times;
  inputs.ids = any_assimp ? "assimp" : "file";
}

}  // namespace snag::cli
