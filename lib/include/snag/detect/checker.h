// Checking a sequence of frames that share one topology: the tree is built once per topology,
// refit every frame (rebuilt when its quality degrades, per RebuildPolicy), traversed, and what
// the double-precision filter cannot certify is decided by an ExactResolver, as the ExactMode
// says (see exact.h).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "snag/detect/backend.h"
#include "snag/detect/exact.h"
#include "snag/detect/result.h"
#include "snag/detect/topology.h"
#include "snag/geom/vec3.h"

namespace snag::detect {

enum class RebuildPolicy { never, automatic, always };

struct CheckSettings {
  RebuildPolicy rebuild = RebuildPolicy::automatic;
  /// With `automatic`, rebuild when the refit tree's quality (sum of internal-node half areas
  /// over the root's half area) exceeds this factor times its value right after the last build.
  double rebuild_threshold = 1.5;
  ExactMode exact = ExactMode::uncertain;
  /// Threads of the exact stage's parallel loops (ExactContext::threads): snag check gives its
  /// checker's, so that --threads caps them too. 0: OpenMP's default (every core).
  int threads = 0;
};

/// One frame handed to Checker::check.
struct FrameInput {
  /// vertex_count entries; valid during the call.
  std::span<const geom::Vec3d> positions;
  /// Per part: 0 when its positions are bit for bit those of the previous check(). Such a
  /// part is not refit, scanned or uploaded again, and checks between parts that did not move
  /// keep their previous pairs (CheckOutcome::reused). Empty: every part moved. Ignored for
  /// the first frame of a topology.
  std::span<const uint8_t> moved;
  /// The frame the next check() will be given, when known: a GPU backend copies it across
  /// while this frame is checked. It must stay valid and unchanged until that check() returns
  /// (a different next frame is merely copied again). `next_moved`: as `moved`, relative to
  /// `positions`.
  std::span<const geom::Vec3d> next_positions;
  std::span<const uint8_t> next_moved;
  /// The caller vouches that every coordinate of `positions` is finite, as snag's readers
  /// guarantee (they reject NaN and infinity with the file and line): check() then skips its
  /// own pass over them. That pass guards the API; in a pipeline, over a frame another thread
  /// has just read, it took ~40 us of an 18K-vertex GPU frame's ~250 on the H100's host.
  bool finite = false;
};

class Checker {
 public:
  /// `resolver` decides what the filter cannot (modes `uncertain`, `all`; `off` decides with
  /// rounded doubles and ignores it); `confirmer` checks every reported pair (mode `all`,
  /// where it is required).
  Checker(std::unique_ptr<Backend> backend, std::shared_ptr<ExactResolver> resolver,
          CheckSettings settings = {}, std::shared_ptr<PairConfirmer> confirmer = nullptr);
  ~Checker();

  /// Sets the triangles of one mesh (indices into each frame's positions), checked against
  /// itself. Returns true when they differ from the current ones, in which case the next
  /// check() builds a new tree.
  bool set_triangles(std::span<const geom::Tri> triangles, int32_t vertex_count);

  /// Sets a scene: several objects (parts) laid end to end as `layout` says, and the pairs of
  /// parts to check (topology.h). Returns true when anything differs from the current scene;
  /// then the next check() builds every part's tree.
  bool set_scene(std::span<const geom::Tri> triangles, int32_t vertex_count, PartLayout layout,
                 std::vector<PartCheck> checks);

  /// Checks one frame. Throws snag::InputError when a coordinate of a part that moved is NaN
  /// or infinite.
  FrameResult check(const FrameInput& frame);
  FrameResult check(std::span<const geom::Vec3d> positions,
                    std::span<const geom::Vec3d> next_positions = {}) {
    return check(FrameInput{positions, {}, next_positions, {}});
  }

  /// Forgets the next frame given to the last check() (FrameInput::next_positions), which a
  /// caller whose run stopped before checking it must call before its span holds anything
  /// else: else a later check() of the same span could take the copy made of the old contents.
  void forget_next_frame() { backend_->stage_part_positions({}, {}); }

  /// The backend's staging memory for frames' positions (Backend::host_staging), or null.
  std::shared_ptr<HostStaging> host_staging(int buffers) { return backend_->host_staging(buffers); }

  /// Tree builds beyond the first of each part of each topology.
  int rebuild_count() const { return rebuilds_; }
  int build_count() const { return builds_; }  ///< tree builds, every part's
  const Topology* topology() const { return topology_.get(); }
  std::string_view backend_name() const { return backend_->name(); }
  const CheckSettings& settings() const { return settings_; }

 private:
  std::unique_ptr<Backend> backend_;
  std::shared_ptr<ExactResolver> resolver_;
  std::shared_ptr<PairConfirmer> confirmer_;
  CheckSettings settings_;
  std::unique_ptr<Topology> topology_;
  /// Per part: its tree must be built at the next check(), and its quality after its last build.
  std::vector<uint8_t> needs_build_;
  std::vector<double> built_quality_;
  /// The last checked frame's degenerate triangles and pairs, kept for the parts and checks of
  /// a frame in which they did not move; `checked_` says whether there is a last frame.
  std::vector<int32_t> last_degenerate_;
  std::vector<FacePair> last_pairs_;
  std::vector<double> last_quality_;
  bool checked_ = false;
  int builds_ = 0;
  int rebuilds_ = 0;
};

}  // namespace snag::detect
