#include "check_sequence.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <vector>

#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/weld.h"
#include "snag/seq/prefetch.h"

namespace snag::cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool same_faces(const std::vector<geom::Tri>& a, const std::vector<geom::Tri>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (a[i].v[k] != b[i].v[k]) return false;
  return true;
}

/// The next frame, or the error reading it, kept for its turn.
struct Upcoming {
  std::optional<seq::PrefetchedFrame> frame;
  std::exception_ptr error;
};

Upcoming take_next(seq::FramePrefetcher& prefetcher) {
  Upcoming next;
  try {
    next.frame = prefetcher.next();
  } catch (...) {
    next.error = std::current_exception();
  }
  return next;
}

}  // namespace

int readers_for(int threads, bool gpu) {
  threads = std::max(threads, 1);
  return gpu ? std::max(threads - 1, 1) : std::clamp(threads / 4, 1, 4);
}

void check_sequence(std::span<const seq::Frame> frames, detect::Checker& checker,
                    const SequenceSettings& settings, report::Inputs& inputs,
                    const std::function<void(report::FrameRecord&&)>& on_frame,
                    const std::function<void(const std::string&)>& warn) {
  std::vector<geom::Tri> file_triangles;  // the current topology, as the file lists it
  std::vector<int32_t> representative;    // weld representative per vertex (empty: no weld)
  int32_t vertex_count = 0;
  std::string first_file;
  bool any_assimp = false;

  // Frames are read ahead on their own threads, each with its own FrameReader (which parses
  // only positions while the faces stay those of its previous frame), while the current one
  // is checked; at most readers + 2 frames are ahead whatever the sequence length.
  const int readers = readers_for(settings.threads, settings.gpu);
  std::vector<io::FrameReader> per_reader(static_cast<size_t>(readers));
  seq::FramePrefetcher prefetcher(std::vector<seq::Frame>(frames.begin(), frames.end()), readers,
                                  readers + 2, [&](const seq::Frame& f, int reader) {
                                    return per_reader[static_cast<size_t>(reader)].read(f.path);
                                  });
  // On a GPU the frame after the current one is taken first, so that its positions cross the
  // bus while the current one is checked. Its error, if reading it failed, waits for its turn.
  Upcoming current = take_next(prefetcher);
  while (current.error || current.frame) {
    if (current.error) std::rethrow_exception(current.error);
    Upcoming following;
    if (settings.gpu) following = take_next(prefetcher);

    const size_t i = current.frame->index;
    const seq::Frame& frame = frames[i];
    const std::string file = frame.path.string();
    const auto read_started = Clock::now();  // welding counts as reading
    mesh::Mesh& mesh = current.frame->mesh;
    any_assimp = any_assimp || mesh.ids_from_assimp;
    const int32_t vertices = static_cast<int32_t>(mesh.positions.size());

    bool topology_changed = false;
    if (i == 0) {
      vertex_count = vertices;
      first_file = file;
    } else if (vertices != vertex_count) {
      throw InputError(file, 0,
                       "has " + std::to_string(vertices) + " vertices, but the first frame (" +
                           first_file + ") has " + std::to_string(vertex_count) +
                           "; every frame of a sequence must have the same vertices");
    } else {
      topology_changed = !same_faces(mesh.triangles, file_triangles);
    }

    if (i == 0 || topology_changed) {
      // Welding is decided once per topology, on its first frame: seams stay closed while the
      // cloth moves, and a weld that changed from frame to frame would rebuild the tree.
      if (settings.weld) {
        representative = mesh::weld_representatives(mesh.positions, *settings.weld);
        int64_t welded = 0;
        for (size_t v = 0; v < representative.size(); ++v)
          welded += representative[v] != static_cast<int32_t>(v);
        if (i == 0) inputs.welded_vertices = welded;
      } else if (i == 0) {
        const int64_t coincident = mesh::count_coincident_vertices(mesh.positions);
        inputs.coincident_vertices = coincident;
        if (coincident > 0)
          warn(file + ": " + std::to_string(coincident) +
               (coincident == 1 ? " vertex coincides" : " vertices coincide") +
               " exactly with another vertex but are separate vertices; unwelded seams are "
               "reported as intersections (use --weld TOL)");
      }
      file_triangles = mesh.triangles;
      checker.set_triangles(mesh::welded_triangles(mesh.triangles, representative), vertex_count);
    }
    const double read_seconds = current.frame->read_seconds + seconds_since(read_started);

    std::span<const geom::Vec3d> next_positions;
    if (following.frame) next_positions = following.frame->mesh.positions;
    const detect::FrameResult result = checker.check(mesh.positions, next_positions);
    report::FrameRecord record = report::make_frame_record(
        frame.number, file, result, mesh.source_polygon, vertices, mesh.polygon_count);
    record.topology_changed = topology_changed;
    record.read_seconds = read_seconds;
    on_frame(std::move(record));

    current = settings.gpu ? std::move(following) : take_next(prefetcher);
  }
  inputs.ids = any_assimp ? "assimp" : "file";
}

}  // namespace snag::cli
