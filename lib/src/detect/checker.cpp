#include "snag/detect/checker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "snag/detect/pairs.h"
#include "snag/detect/resolve.h"
#include "snag/detect/topology.h"
#include "snag/error.h"

namespace snag::detect {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Checker::Checker(std::unique_ptr<Backend> backend, std::shared_ptr<ExactResolver> resolver,
                 CheckSettings settings, std::shared_ptr<PairConfirmer> confirmer)
    : backend_(std::move(backend)),
      resolver_(std::move(resolver)),
      confirmer_(std::move(confirmer)),
      settings_(settings) {
  if (settings_.exact == ExactMode::off) resolver_ = make_rounded_resolver();
  if (!backend_ || !resolver_) throw InternalError("Checker needs a backend and an exact resolver");
  if (settings_.exact == ExactMode::all && !confirmer_)
    throw InternalError("--exact all needs a pair confirmer");
}

Checker::~Checker() = default;

bool Checker::set_triangles(std::span<const geom::Tri> triangles, int32_t vertex_count) {
  if (topology_ && topology_->vertex_count == vertex_count &&
      topology_->triangles.size() == triangles.size() &&
      std::equal(triangles.begin(), triangles.end(), topology_->triangles.begin(),
                 [](const geom::Tri& x, const geom::Tri& y) {
                   return x.v[0] == y.v[0] && x.v[1] == y.v[1] && x.v[2] == y.v[2];
                 }))
    return false;
  topology_ = std::make_unique<Topology>(make_topology(triangles, vertex_count));
  backend_->set_topology(*topology_);
  needs_build_ = true;
  return true;
}

FrameResult Checker::check(std::span<const geom::Vec3d> positions,
                           std::span<const geom::Vec3d> next_positions) {
  if (!topology_) throw InternalError("Checker::check called before set_triangles");
  if (static_cast<int64_t>(positions.size()) != topology_->vertex_count)
    throw InternalError("frame has " + std::to_string(positions.size()) +
                        " vertices, topology has " + std::to_string(topology_->vertex_count));
  // Every decision assumes finite coordinates (NaN compares false everywhere, and CGAL cannot
  // convert infinity to an exact number). Readers reject such files; this guards the API. A
  // coordinate minus itself is 0 unless it is NaN or infinite, so one sum tells.
  double poison = 0;
  for (const geom::Vec3d& p : positions) poison += (p.x - p.x) + (p.y - p.y) + (p.z - p.z);
  if (poison != 0) {  // NaN != 0 too
    for (size_t v = 0; v < positions.size(); ++v)
      if (!std::isfinite(positions[v].x) || !std::isfinite(positions[v].y) ||
          !std::isfinite(positions[v].z))
        throw InputError("frame", 0,
                         "vertex " + std::to_string(v) +
                             " has a NaN or infinite coordinate; expected finite numbers");
  }
  FrameResult result;
  if (topology_->triangle_count() == 0) return result;
  const ExactContext context{positions, topology_.get()};
  backend_->set_positions(positions);
  if (!next_positions.empty()) backend_->stage_positions(next_positions);

  // Zero-area triangles first: they are left out of the search and own no edges. Mode `all`
  // decides every triangle exactly.
  const bool exact_all = settings_.exact == ExactMode::all;
  DegeneracyScan scan;
  if (exact_all) {
    scan.uncertain.resize(static_cast<size_t>(topology_->triangle_count()));
    std::iota(scan.uncertain.begin(), scan.uncertain.end(), 0);
  } else {
    scan = backend_->scan_degenerate();
  }
  result.degenerate = std::move(scan.degenerate);
  if (!scan.uncertain.empty()) {
    const auto start = Clock::now();
    std::vector<uint8_t> degenerate(scan.uncertain.size());
    resolver_->degenerate(context, scan.uncertain, degenerate);
    for (size_t i = 0; i < scan.uncertain.size(); ++i)
      if (degenerate[i]) result.degenerate.push_back(scan.uncertain[i]);
    std::sort(result.degenerate.begin(), result.degenerate.end());
    result.uncertain_tests += static_cast<int64_t>(scan.uncertain.size());
    result.times.exact += seconds_since(start);
  }

  // The tree: built once per topology, refit every frame, rebuilt as the policy says.
  auto build = [&](bool is_rebuild) {
    const auto start = Clock::now();
    backend_->build();
    result.times.build += seconds_since(start);
    result.rebuilt = true;
    ++builds_;
    rebuilds_ += is_rebuild;
    needs_build_ = false;
    built_quality_ = backend_->tree_quality();
  };
  if (needs_build_) {
    build(false);
  } else if (settings_.rebuild == RebuildPolicy::always) {
    build(true);
  } else {
    const auto start = Clock::now();
    backend_->refit();
    result.times.refit = seconds_since(start);
    if (settings_.rebuild == RebuildPolicy::automatic && built_quality_ > 0 &&
        backend_->tree_quality() > settings_.rebuild_threshold * built_quality_)
      build(true);
  }
  result.tree_quality = backend_->tree_quality();

  FilteredFrame frame =
      backend_->detect(result.degenerate, exact_all ? FilterUse::defer_all : FilterUse::certify);
  result.times.traverse = frame.traverse_seconds;
  result.times.classify = frame.classify_seconds;
  result.candidate_pairs = frame.candidate_pairs;
  // With `all`, the kinds the backend classified (of duplicated faces) are decided again below.
  result.filtered_tests = exact_all ? 0 : frame.filtered_tests;

  // What the filter could not certify: edge-triangle tests, then the kinds of pairs.
  const auto exact_start = Clock::now();
  if (!frame.uncertain.empty()) {
    std::vector<uint8_t> hit(frame.uncertain.size());
    resolver_->edge_hits(context, frame.uncertain, hit);
    std::vector<EdgeTriangleTask> hits;
    for (size_t i = 0; i < frame.uncertain.size(); ++i)
      if (hit[i]) hits.push_back(frame.uncertain[i]);
    result.uncertain_tests += static_cast<int64_t>(frame.uncertain.size());
    if (!hits.empty()) {
      std::vector<uint8_t> degenerate_flags(static_cast<size_t>(topology_->triangle_count()), 0);
      for (int32_t t : result.degenerate) degenerate_flags[t] = 1;
      std::vector<FacePair> found = expand_hits(*topology_, hits, degenerate_flags);
      // Their kinds: by the filter where it can, unless `all` decides every kind below.
      std::vector<uint8_t> certain(found.size(), 0);
      if (!exact_all) classify_pairs(positions, *topology_, found, certain, 1);
      merge_pairs(frame.pairs, frame.kind_certain, found, certain);
    }
  }
  std::vector<FacePair> unclassified;
  std::vector<size_t> where;
  for (size_t i = 0; i < frame.pairs.size(); ++i)
    if (!frame.kind_certain[i] || exact_all) {
      unclassified.push_back(frame.pairs[i]);
      where.push_back(i);
    }
  if (!unclassified.empty()) {
    std::vector<PairKind> kinds(unclassified.size());
    resolver_->pair_kinds(context, unclassified, kinds);
    for (size_t i = 0; i < where.size(); ++i) frame.pairs[where[i]].kind = kinds[i];
    result.uncertain_tests += static_cast<int64_t>(unclassified.size());
  }
  result.times.exact += seconds_since(exact_start);
  result.pairs = std::move(frame.pairs);

  if (exact_all) {
    const auto confirm_start = Clock::now();
    const std::vector<Disagreement> wrong = confirmer_->confirm(context, result.pairs);
    if (!wrong.empty()) {
      std::string message = "the independent check contradicts " + std::to_string(wrong.size()) +
                            " reported pair(s):";
      for (size_t i = 0; i < std::min<size_t>(wrong.size(), 10); ++i)
        message += " (" + std::to_string(wrong[i].pair.a) + ", " + std::to_string(wrong[i].pair.b) +
                   ", " + std::string(to_string(wrong[i].pair.kind)) + ": " + wrong[i].what + ")";
      throw InternalError(message);
    }
    result.confirmed_pairs = static_cast<int64_t>(result.pairs.size());
    result.times.confirm = seconds_since(confirm_start);
  }
  return result;
}

}  // namespace snag::detect
