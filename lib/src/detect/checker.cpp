#include "snag/detect/checker.h"

#include <algorithm>
#include <chrono>

#include "snag/detect/pairs.h"
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
                 CheckSettings settings)
    : backend_(std::move(backend)), resolver_(std::move(resolver)), settings_(settings) {
  if (!backend_ || !resolver_) throw InternalError("Checker needs a backend and an exact resolver");
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

FrameResult Checker::check(std::span<const geom::Vec3d> positions) {
  if (!topology_) throw InternalError("Checker::check called before set_triangles");
  if (static_cast<int64_t>(positions.size()) != topology_->vertex_count)
    throw InternalError("frame has " + std::to_string(positions.size()) +
                        " vertices, topology has " + std::to_string(topology_->vertex_count));
  FrameResult result;
  if (topology_->triangle_count() == 0) return result;
  const ExactContext context{positions, topology_.get()};
  backend_->set_positions(positions);

  // Zero-area triangles first: they are left out of the search and own no edges.
  DegeneracyScan scan = backend_->scan_degenerate();
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

  FilteredFrame frame = backend_->detect(result.degenerate);
  result.times.traverse = frame.traverse_seconds;
  result.times.classify = frame.classify_seconds;
  result.candidate_pairs = frame.candidate_pairs;
  result.filtered_tests = frame.filtered_tests;

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
      std::vector<uint8_t> certain;
      classify_pairs(positions, *topology_, found, certain, 1);
      merge_pairs(frame.pairs, frame.kind_certain, found, certain);
    }
  }
  std::vector<FacePair> unclassified;
  std::vector<size_t> where;
  for (size_t i = 0; i < frame.pairs.size(); ++i)
    if (!frame.kind_certain[i]) {
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
  return result;
}

}  // namespace snag::detect
