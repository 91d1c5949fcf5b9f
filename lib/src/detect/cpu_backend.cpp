#include "snag/detect/cpu_backend.h"

#include <omp.h>

#include <algorithm>
#include <chrono>

#include "snag/bvh/tree.h"
#include "snag/detect/pair_test.h"
#include "snag/detect/pairs.h"
#include "snag/geom/narrow_phase.h"

namespace snag::detect {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Per-thread results: no lock per appended result; merged after the parallel loop.
struct ThreadSink {
  std::vector<EdgeTriangleTask> hits;
  std::vector<EdgeTriangleTask> uncertain_tests;
  std::vector<FacePair> duplicates;
  int64_t misses = 0;
  int64_t candidates = 0;

  void hit(int32_t edge, int32_t triangle) { hits.push_back({edge, triangle}); }
  void uncertain(int32_t edge, int32_t triangle) { uncertain_tests.push_back({edge, triangle}); }
  void miss() { ++misses; }
  void duplicate(int32_t a, int32_t b) {
    duplicates.push_back({std::min(a, b), std::max(a, b), PairKind::touching});
  }
};

class CpuBackend final : public Backend {
 public:
  explicit CpuBackend(int threads) : threads_(threads > 0 ? threads : omp_get_max_threads()) {}

  std::string_view name() const override { return "cpu"; }

  void set_topology(const Topology& topology) override { topology_ = &topology; }

  void set_positions(std::span<const geom::Vec3d> positions) override { positions_ = positions; }

  DegeneracyScan scan_degenerate() override {
    const geom::FilteredPredicates pred{positions_.data()};
    const int32_t n = topology_->triangle_count();
    std::vector<uint8_t> answer(static_cast<size_t>(n));
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (int32_t t = 0; t < n; ++t) {
      const geom::Tri tri = topology_->triangles[t];
      answer[t] = static_cast<uint8_t>(geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]));
    }
    DegeneracyScan scan;
    for (int32_t t = 0; t < n; ++t) {
      if (answer[t] == static_cast<uint8_t>(geom::Answer::yes)) scan.degenerate.push_back(t);
      if (answer[t] == static_cast<uint8_t>(geom::Answer::uncertain)) scan.uncertain.push_back(t);
    }
    return scan;
  }

  void build() override {
    tree_.build(mesh_view(), threads_);
  }
  void refit() override {
    tree_.refit(mesh_view(), threads_);
  }
  double tree_quality() override {
    return tree_.quality();
  }

  FilteredFrame detect(std::span<const int32_t> degenerate, FilterUse use) override {
    return use == FilterUse::certify ? detect_with<FilterUse::certify>(degenerate)
                                     : detect_with<FilterUse::defer_all>(degenerate);
  }

 private:
  template <FilterUse use>
  FilteredFrame detect_with(std::span<const int32_t> degenerate) {
    const Topology& topo = *topology_;
    const int32_t n = topo.triangle_count();
    FilteredFrame frame;
    const auto start = Clock::now();

    std::vector<uint8_t> degenerate_flags(static_cast<size_t>(n), 0);
    for (int32_t t : degenerate) degenerate_flags[t] = 1;
    const std::vector<uint8_t> owned = ownership_without(topo, degenerate);
    const TopologyView view{topo.triangles.data(),
                            topo.edges.data(),
                            topo.triangle_edges.data(),
                            owned.data(),
                            topo.listed_vertex.data(),
                            topo.every_vertex_listed,
                            n,
                            static_cast<int32_t>(topo.edges.size())};
    planes_.resize(static_cast<size_t>(n));
    if constexpr (use == FilterUse::certify) {
#pragma omp parallel for num_threads(threads_) schedule(static)
      for (int32_t t = 0; t < n; ++t)
        planes_[t] = triangle_plane(positions_.data(), topo.triangles[t]);
    }
    const FrameView frame_view{positions_.data(), planes_.data()};
    const bvh::TreeView tree = tree_.view();

    std::vector<ThreadSink> sinks(static_cast<size_t>(threads_));
#pragma omp parallel num_threads(threads_)
    {
      ThreadSink& sink = sinks[static_cast<size_t>(omp_get_thread_num())];
      // Neighbour pairs from their list: their boxes always overlap.
      const auto neighbor_count = static_cast<int64_t>(topo.neighbor_pairs.size());
#pragma omp for schedule(static) nowait
      for (int64_t i = 0; i < neighbor_count; ++i) {
        const auto [t, x] = topo.neighbor_pairs[i];
        if (degenerate_flags[t] || degenerate_flags[x]) continue;
        ++sink.candidates;
        const uint32_t shared = topo.neighbor_shared[i];
        test_pair<use>(frame_view, view, t, x, shared & 7u, shared >> 3, sink);
      }
      // The other candidates from the traversal: the leaves of each group of up to four
      // consecutive positions walk the tree together (for_each_later_overlap_grouped), groups
      // in leaf order; dynamic chunks because groups in dense regions cost more.
      const int32_t level = bvh::group_level(tree.shape);
      const int32_t first_group = bvh::CompleteTree::level_begin(level);
      const int32_t last_group =
          std::min(bvh::CompleteTree::level_begin(level + 1), tree.shape.node_count());
#pragma omp for schedule(dynamic, 64)
      for (int32_t group = first_group; group < last_group; ++group) {
        bvh::for_each_later_overlap_grouped(tree, group, [&](int32_t t, int32_t x) {
          if (degenerate_flags[t] || degenerate_flags[x] ||
              is_listed_neighbor(topo.triangles[t], topo.triangles[x], view.listed_vertex,
                                 view.every_vertex_listed))
            return;
          ++sink.candidates;
          test_candidate_pair<use>(frame_view, view, t, x, sink);
        });
      }
    }

    std::vector<EdgeTriangleTask> hits;
    std::vector<FacePair> duplicates;
    for (ThreadSink& sink : sinks) {
      hits.insert(hits.end(), sink.hits.begin(), sink.hits.end());
      frame.uncertain.insert(frame.uncertain.end(), sink.uncertain_tests.begin(),
                             sink.uncertain_tests.end());
      duplicates.insert(duplicates.end(), sink.duplicates.begin(), sink.duplicates.end());
      frame.candidate_pairs += sink.candidates;
      frame.filtered_tests += sink.misses + static_cast<int64_t>(sink.hits.size());
    }
    // Thread scheduling decides the order of the merged lists; sorting makes it canonical.
    std::sort(frame.uncertain.begin(), frame.uncertain.end(),
              [](const EdgeTriangleTask& x, const EdgeTriangleTask& y) {
                return x.edge != y.edge ? x.edge < y.edge : x.triangle < y.triangle;
              });
    frame.traverse_seconds = seconds_since(start);

    const auto classify_start = Clock::now();
    frame.pairs = expand_hits(topo, hits, degenerate_flags);
    std::sort(duplicates.begin(), duplicates.end(), [](const FacePair& x, const FacePair& y) {
      return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    std::vector<uint8_t> pair_flags(frame.pairs.size(), 1), duplicate_flags(duplicates.size(), 1);
    merge_pairs(frame.pairs, pair_flags, duplicates, duplicate_flags);
    const int64_t uncertain_kinds =
        classify_pairs(positions_, topo, frame.pairs, frame.kind_certain, threads_, planes_.data());
    frame.filtered_tests += static_cast<int64_t>(frame.pairs.size()) - uncertain_kinds;
    frame.classify_seconds = seconds_since(classify_start);
    return frame;
  }

  mesh::MeshView mesh_view() const {
    return {positions_.data(), topology_->triangles.data(), static_cast<int32_t>(positions_.size()),
            topology_->triangle_count()};
  }

  int threads_;
  const Topology* topology_ = nullptr;
  std::span<const geom::Vec3d> positions_;
  std::vector<geom::PlaneCoefficients> planes_;  ///< per triangle, this frame
  bvh::Tree tree_;
};

}  // namespace

std::unique_ptr<Backend> make_cpu_backend(int threads) {
  return std::make_unique<CpuBackend>(threads);
}

}  // namespace snag::detect
