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
#include "snag/geom/vec3.h"

namespace snag::detect {

enum class RebuildPolicy { never, automatic, always };

struct CheckSettings {
  RebuildPolicy rebuild = RebuildPolicy::automatic;
  /// With `automatic`, rebuild when the refit tree's quality (sum of internal-node half areas
  /// over the root's half area) exceeds this factor times its value right after the last build.
  double rebuild_threshold = 1.5;
  ExactMode exact = ExactMode::uncertain;
};

class Checker {
 public:
  /// `resolver` decides what the filter cannot (modes `uncertain`, `all`; `off` decides with
  /// rounded doubles and ignores it); `confirmer` checks every reported pair (mode `all`,
  /// where it is required).
  Checker(std::unique_ptr<Backend> backend, std::shared_ptr<ExactResolver> resolver,
          CheckSettings settings = {}, std::shared_ptr<PairConfirmer> confirmer = nullptr);
  ~Checker();

  /// Sets the triangles (indices into each frame's positions). Returns true when they differ
  /// from the current ones, in which case the next check() builds a new tree.
  bool set_triangles(std::span<const geom::Tri> triangles, int32_t vertex_count);

  /// Checks one frame. `positions` has vertex_count entries and must stay valid during the call.
  /// Throws snag::InputError when a coordinate is NaN or infinite.
  ///
  /// `next_positions`, when given, are the frame the next check() will be given: a GPU backend
  /// copies them across while this frame is checked. They must stay valid and unchanged until
  /// that check() returns (a different next frame is merely copied again).
  FrameResult check(std::span<const geom::Vec3d> positions,
                    std::span<const geom::Vec3d> next_positions = {});

  int rebuild_count() const { return rebuilds_; }  ///< builds other than the first of each topology
  int build_count() const { return builds_; }
  std::string_view backend_name() const { return backend_->name(); }
  const CheckSettings& settings() const { return settings_; }

 private:
  std::unique_ptr<Backend> backend_;
  std::shared_ptr<ExactResolver> resolver_;
  std::shared_ptr<PairConfirmer> confirmer_;
  CheckSettings settings_;
  std::unique_ptr<struct Topology> topology_;
  bool needs_build_ = true;
  double built_quality_ = 0;
  int builds_ = 0;
  int rebuilds_ = 0;
};

}  // namespace snag::detect
