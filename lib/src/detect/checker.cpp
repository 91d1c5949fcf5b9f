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
    throw InternalError("Checker: ExactMode::all needs a pair confirmer");
}

Checker::~Checker() = default;

bool Checker::set_triangles(std::span<const geom::Tri> triangles, int32_t vertex_count) {
  PartLayout layout;
  layout.triangle_begin = {0, static_cast<int32_t>(triangles.size())};
  layout.vertex_begin = {0, vertex_count};
  return set_scene(triangles, vertex_count, std::move(layout), {PartCheck{0, 0}});
}

bool Checker::set_scene(std::span<const geom::Tri> triangles, int32_t vertex_count,
                        PartLayout layout, std::vector<PartCheck> checks) {
  Topology next =
      make_scene_topology(triangles, vertex_count, std::move(layout), std::move(checks));
  if (topology_ && topology_->vertex_count == vertex_count &&
      topology_->layout.triangle_begin == next.layout.triangle_begin &&
      topology_->layout.vertex_begin == next.layout.vertex_begin &&
      topology_->checks == next.checks && topology_->triangles.size() == triangles.size() &&
      std::equal(triangles.begin(), triangles.end(), topology_->triangles.begin(),
                 [](const geom::Tri& x, const geom::Tri& y) {
                   return x.v[0] == y.v[0] && x.v[1] == y.v[1] && x.v[2] == y.v[2];
                 }))
    return false;
  topology_ = std::make_unique<Topology>(std::move(next));
  backend_->set_topology(*topology_);
  const auto parts = static_cast<size_t>(topology_->part_count());
  needs_build_.assign(parts, 1);
  built_quality_.assign(parts, 0.0);
  last_quality_.assign(parts, 0.0);
  checked_ = false;
  return true;
}

namespace {

/// The index in topology.checks of the check pair `p` comes from (-1 for none).
int64_t check_of(const Topology& topology, const FacePair& p) {
  if (topology.checks.size() == 1) return 0;
  const PartCheck check{topology.part_of(p.a), topology.part_of(p.b)};
  const auto at = std::lower_bound(topology.checks.begin(), topology.checks.end(), check);
  return at != topology.checks.end() && *at == check ? at - topology.checks.begin() : -1;
}

/// The pairs of `pairs` (sorted) whose check is one of those flagged in `keep` (per check).
std::vector<FacePair> pairs_of_checks(const Topology& topology, std::span<const FacePair> pairs,
                                      const std::vector<uint8_t>& keep) {
  std::vector<FacePair> kept;
  for (const FacePair& p : pairs) {
    const int64_t c = check_of(topology, p);
    if (c >= 0 && keep[c]) kept.push_back(p);
  }
  return kept;
}

}  // namespace

FrameResult Checker::check(const FrameInput& input) {
  if (!topology_) throw InternalError("Checker::check called before set_triangles");
  const std::span<const geom::Vec3d> positions = input.positions;
  if (static_cast<int64_t>(positions.size()) != topology_->vertex_count)
    throw InternalError("frame has " + std::to_string(positions.size()) +
                        " vertices, topology has " + std::to_string(topology_->vertex_count));
  const Topology& topo = *topology_;
  const int32_t part_count = topo.part_count();
  // Which parts moved since the last frame: all of them in a topology's first frame.
  std::vector<uint8_t> moved(static_cast<size_t>(part_count), 1);
  if (checked_ && !input.moved.empty()) {
    if (static_cast<int32_t>(input.moved.size()) != part_count)
      throw InternalError("FrameInput::moved has " + std::to_string(input.moved.size()) +
                          " entries for " + std::to_string(part_count) + " parts");
    for (int32_t p = 0; p < part_count; ++p) moved[p] = input.moved[p] != 0;
  }
  // Every decision assumes finite coordinates (NaN compares false everywhere, and CGAL cannot
  // convert infinity to an exact number). Readers reject such files; this guards the API
  // (FrameInput::finite). A coordinate minus itself is 0 unless it is NaN or infinite, so one
  // sum tells.
  for (int32_t p = 0; p < part_count; ++p) {
    if (!moved[p] || input.finite) continue;
    double poison = 0;
    for (int32_t v = topo.layout.vertex_begin[p]; v < topo.layout.vertex_begin[p + 1]; ++v)
      poison += (positions[v].x - positions[v].x) + (positions[v].y - positions[v].y) +
                (positions[v].z - positions[v].z);
    if (poison == 0) continue;  // NaN != 0 too
    for (int32_t v = topo.layout.vertex_begin[p]; v < topo.layout.vertex_begin[p + 1]; ++v)
      if (!std::isfinite(positions[v].x) || !std::isfinite(positions[v].y) ||
          !std::isfinite(positions[v].z))
        throw InputError("frame", 0,
                         "vertex " + std::to_string(v) +
                             " has a NaN or infinite coordinate; expected finite numbers");
  }
  FrameResult result;
  result.parts.resize(static_cast<size_t>(part_count));
  for (int32_t p = 0; p < part_count; ++p) result.parts[p].moved = moved[p];
  if (topo.triangle_count() == 0) {
    checked_ = true;
    for (const PartCheck& c : topo.checks) result.checks.push_back({c.a, c.b, 0, false, 0.0});
    return result;
  }
  const ExactContext context{positions, topology_.get(), settings_.threads};
  backend_->set_part_positions(positions, moved);
  if (!input.next_positions.empty())
    backend_->stage_part_positions(input.next_positions, input.next_moved);

  // Zero-area triangles first: they are left out of the search and own no edges. Mode `all`
  // decides every triangle exactly. Parts that did not move keep their last frame's.
  const bool exact_all = settings_.exact == ExactMode::all;
  std::vector<int32_t> moved_parts;
  for (int32_t p = 0; p < part_count; ++p)
    if (moved[p]) moved_parts.push_back(p);
  DegeneracyScan scan;
  if (exact_all) {
    for (int32_t p : moved_parts)
      for (int32_t t = topo.layout.triangle_begin[p]; t < topo.layout.triangle_begin[p + 1]; ++t)
        scan.uncertain.push_back(t);
  } else if (!moved_parts.empty()) {
    const auto start = Clock::now();
    scan = backend_->scan_degenerate_parts(moved_parts);
    result.times.scan = seconds_since(start);
  }
  result.degenerate = std::move(scan.degenerate);
  for (int32_t t : last_degenerate_)
    if (!moved[topo.part_of(t)]) result.degenerate.push_back(t);
  if (!scan.uncertain.empty()) {
    const auto start = Clock::now();
    std::vector<uint8_t> degenerate(scan.uncertain.size());
    resolver_->degenerate(context, scan.uncertain, degenerate);
    for (size_t i = 0; i < scan.uncertain.size(); ++i)
      if (degenerate[i]) result.degenerate.push_back(scan.uncertain[i]);
    result.uncertain_tests += static_cast<int64_t>(scan.uncertain.size());
    result.times.exact += seconds_since(start);
  }
  std::sort(result.degenerate.begin(), result.degenerate.end());

  // The trees: built once per topology, refit every frame their part moves, rebuilt as the
  // policy says.
  for (int32_t p = 0; p < part_count; ++p) {
    PartOutcome& part = result.parts[p];
    auto build = [&](bool is_rebuild) {
      const auto start = Clock::now();
      backend_->build_part(p);
      part.build_seconds += seconds_since(start);
      part.rebuilt = true;
      ++builds_;
      rebuilds_ += is_rebuild;
      needs_build_[p] = 0;
      built_quality_[p] = backend_->part_quality(p);
    };
    if (needs_build_[p]) {
      build(false);
    } else if (!moved[p]) {
      // Nothing to refit: the tree fits these positions already.
    } else if (settings_.rebuild == RebuildPolicy::always) {
      build(true);
    } else {
      const auto start = Clock::now();
      backend_->refit_part(p);
      part.refit_seconds = seconds_since(start);
      // Asked once: on the CPU the quality is a pass over every internal node.
      last_quality_[p] = backend_->part_quality(p);
      // A tree built on a frame of no extent (every triangle at one point: a zeroed frame) has
      // quality 0, to which no ratio compares: the first frame with a quality rebuilds it.
      const double built = built_quality_[p], now = last_quality_[p];
      const bool degraded = built > 0 ? now > settings_.rebuild_threshold * built : now > 0;
      if (settings_.rebuild == RebuildPolicy::automatic && degraded) build(true);
    }
    if (part.rebuilt) last_quality_[p] = built_quality_[p];
    part.tree_quality = last_quality_[p];
    result.times.build += part.build_seconds;
    result.times.refit += part.refit_seconds;
    result.rebuilt = result.rebuilt || part.rebuilt;
  }
  result.tree_quality = result.parts[0].tree_quality;

  // The checks with a part that moved; the others keep their last frame's pairs.
  std::vector<int32_t> run;
  std::vector<uint8_t> reused(topo.checks.size(), 0);
  for (size_t c = 0; c < topo.checks.size(); ++c) {
    if (moved[topo.checks[c].a] || moved[topo.checks[c].b])
      run.push_back(static_cast<int32_t>(c));
    else
      reused[c] = 1;
  }
  FilteredFrame frame;
  if (!run.empty())
    frame = backend_->detect_checks(result.degenerate,
                                    exact_all ? FilterUse::defer_all : FilterUse::certify, run);
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

  if (exact_all && !result.pairs.empty()) {
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

  // The pairs of the checks not run: the last frame's, decided (and confirmed) then.
  if (!run.empty() && run.size() < topo.checks.size()) {
    std::vector<FacePair> kept = pairs_of_checks(topo, last_pairs_, reused);
    std::vector<FacePair> merged(result.pairs.size() + kept.size());
    std::merge(
        result.pairs.begin(), result.pairs.end(), kept.begin(), kept.end(), merged.begin(),
        [](const FacePair& x, const FacePair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    result.pairs = std::move(merged);
  } else if (run.empty()) {
    result.pairs = last_pairs_;
  }

  // Per check: its pairs, and its time when it ran.
  result.checks.resize(topo.checks.size());
  for (size_t c = 0; c < topo.checks.size(); ++c)
    result.checks[c] = {topo.checks[c].a, topo.checks[c].b, 0, reused[c] != 0, 0.0};
  for (size_t i = 0; i < run.size() && i < frame.check_seconds.size(); ++i)
    result.checks[run[i]].seconds = frame.check_seconds[i];
  for (const FacePair& p : result.pairs) {
    const int64_t c = check_of(topo, p);
    if (c < 0) throw InternalError("a pair between parts that are not checked together");
    ++result.checks[c].pairs;
  }

  last_pairs_ = result.pairs;
  last_degenerate_ = result.degenerate;
  checked_ = true;
  return result;
}

}  // namespace snag::detect
