#include "snag/detect/cpu_backend.h"

#include <omp.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <optional>

#include "snag/bvh/leaf_lanes.h"
#include "snag/bvh/tree.h"
#include "snag/detect/fan.h"
#include "snag/detect/lane_screen.h"
#include "snag/detect/pair_test.h"
#include "snag/detect/pairs.h"
#include "snag/geom/narrow_phase.h"
#include "snag/threads.h"

namespace snag::detect {

namespace {

using Clock = std::chrono::steady_clock;

/// A part's per-triangle and per-vertex loops (the degenerate scan, planes, fans) run on the
/// calling thread up to this many items (for_each_index): a small object of a scene then costs
/// no parallel region, each about a microsecond, and a fan's ~55 ns (the dearest item) times
/// 256 is still short.
constexpr int64_t kSerialItems = 256;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Per-thread results: no lock per appended result; merged after the parallel loop. Each on
/// cache lines of its own: a thread counts every candidate and miss in its sink, and sinks side
/// by side put one thread's counters on the line of the next one's vectors, which it writes at
/// every hit.
struct alignas(64) ThreadSink {
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

/// The corners' vertex ids of a group's (up to W) lanes, one vector per corner (-1 in absent
/// lanes), to find in one pass which lanes share a vertex with a triangle.
template <int W>
struct LaneCorners {
  typename bvh::LeafLanes<W>::Mask v[3];

  LaneCorners(const bvh::LeafLanes<W>& lanes, const geom::Tri* triangles) {
    for (int lane = 0; lane < W; ++lane)
      for (int k = 0; k < 3; ++k)
        v[k][lane] = lane < lanes.members ? triangles[lanes.triangle[lane]].v[k] : -1;
  }

  /// A bit per lane whose triangle has a vertex of `x`.
  uint32_t sharing(const geom::Tri& x) const {
    typename bvh::LeafLanes<W>::Mask any{};
    for (int k = 0; k < 3; ++k) any |= (v[0] == x.v[k]) | (v[1] == x.v[k]) | (v[2] == x.v[k]);
    return bvh::LeafLanes<W>::bits(any);
  }
};

/// Of the lanes in `sharing` (those sharing a vertex with xt), the ones whose shared vertices
/// include a listed one: their pairs with xt are in the neighbour list.
template <int W>
uint32_t listed_among(uint32_t sharing, const bvh::LeafLanes<W>& lanes, int32_t base,
                      const geom::Tri& xt, const TopologyView& view) {
  uint32_t listed = 0;
  for (uint32_t bits = sharing; bits; bits &= bits - 1) {
    const int lane = bvh::count_trailing_zeros(bits);
    if (is_listed_neighbor(view.triangles[base + lanes.triangle[lane]], xt, view.listed_vertex,
                           false))
      listed |= 1u << lane;
  }
  return listed;
}

/// What a check's walks read: the tree walked (the whole part for a self check, the larger part
/// of two), where its triangle ids start, and for two parts the other part's tree and base.
struct WalkInput {
  bvh::TreeView tree;
  int32_t base = 0;
  bvh::TreeView other;
  int32_t other_base = 0;
  const FrameView* frame = nullptr;
  const TopologyView* view = nullptr;
  const uint8_t* degenerate = nullptr;
};

/// The candidate pairs of the group's lanes in `todo` with triangle x (not degenerate), which
/// the walk reached: their rejection by sides and the test of segments apart are taken for all
/// of them at once (LaneScreen::settle, `screen` loaded at the group's first use), and only the
/// pairs it leaves get the pair test. Lanes in `sharing` have a vertex of x (a weld left it
/// unlisted): the screen assumes none, so they get the whole pair test.
template <int W, FilterUse use>
inline void test_lanes_against(const WalkInput& in, const bvh::LeafLanes<W>& lanes,
                               std::optional<LaneScreen<W>>& screen, uint32_t todo,
                               uint32_t sharing, int32_t x, const geom::Tri& xt, ThreadSink& sink) {
  const TopologyView& view = *in.view;
  const FrameView& frame = *in.frame;
  typename LaneScreen<W>::Settled settled;
  if constexpr (use == FilterUse::certify) {  // the planes exist only then
    if (const uint32_t screened = todo & ~sharing) {
      if (!screen) screen.emplace(lanes.triangle, lanes.members, frame, view.triangles, in.base);
      settled = screen->settle(frame.positions, frame.planes[x], xt, screened);
    }
  }
  for (; todo; todo &= todo - 1) {
    const int lane = bvh::count_trailing_zeros(todo);
    const int32_t t = in.base + lanes.triangle[lane];
    if (in.degenerate[t]) continue;
    ++sink.candidates;
    // What test_pair would end with: nothing to report, or a miss for each edge tested (every
    // edge either triangle represents: they share no vertex).
    if (settled.separated & (1u << lane)) continue;
    if (settled.apart & (1u << lane)) {
      sink.misses +=
          std::popcount(view.owned_edges[t] & 7u) + std::popcount(view.owned_edges[x] & 7u);
      continue;
    }
    if (sharing & (1u << lane))
      test_candidate_pair<use>(frame, view, t, x, sink);
    else
      test_pair<use>(frame, view, t, x, 0, 0, sink);
  }
}

/// The later leaves of a self check for the leaves under node `group` (LeafLanes::for_each_later).
/// At each leaf the walk reaches, the lanes that share a vertex with it are found together;
/// when every vertex is listed (no weld left some out) they are dropped at once, else lane by
/// lane (listed_among). The other lanes' pairs with it are candidates (test_lanes_against).
template <int W, FilterUse use>
inline void walk_self_group(const WalkInput& in, int32_t group, ThreadSink& sink) {
  const TopologyView& view = *in.view;
  const bvh::LeafLanes<W> lanes(in.tree, group);
  const LaneCorners<W> corners(lanes, view.triangles + in.base);
  // Loaded at the group's first candidate: in a settled cloth most groups meet only neighbours.
  std::optional<LaneScreen<W>> screen;
  lanes.for_each_later(in.tree, group, [&](uint32_t overlapping, int32_t local_x) {
    const int32_t x = in.base + local_x;
    const geom::Tri xt = view.triangles[x];
    const uint32_t sharing_any = corners.sharing(xt);
    uint32_t sharing = sharing_any;
    // Most overlapping leaves are listed neighbours of every lane they overlap (94% of the
    // overlaps of a settled 36K cloth frame): they end here, after a few compares.
    if (!view.every_vertex_listed) sharing = listed_among(sharing, lanes, in.base, xt, view);
    const uint32_t todo = overlapping & ~sharing;
    if (!todo || in.degenerate[x]) return;
    test_lanes_against<W, use>(in, lanes, screen, todo, sharing_any, x, xt, sink);
  });
}

/// The leaves under node `group` of in.tree against every leaf of in.other: two parts share no
/// vertex, so every overlap is a candidate (test_lanes_against; the lanes sharing one are still
/// looked for, at the cost of a few compares, so that nothing rests on that).
template <int W, FilterUse use>
inline void walk_between_group(const WalkInput& in, int32_t group, ThreadSink& sink) {
  const TopologyView& view = *in.view;
  const bvh::LeafLanes<W> lanes(in.tree, group);
  const LaneCorners<W> corners(lanes, view.triangles + in.base);
  std::optional<LaneScreen<W>> screen;
  lanes.walk_leaves(in.other, 0, [&](uint32_t overlapping, int32_t local_x) {
    const int32_t x = in.other_base + local_x;
    if (in.degenerate[x]) return;
    const geom::Tri xt = view.triangles[x];
    test_lanes_against<W, use>(in, lanes, screen, overlapping, corners.sharing(xt), x, xt, sink);
  });
}

/// Which walk a check's groups run: a part against its own later leaves, or against the other
/// part's whole tree.
enum class GroupWalk { self, between };

template <GroupWalk kind, int W, FilterUse use>
inline void walk_group(const WalkInput& in, int32_t group, ThreadSink& sink) {
  if constexpr (kind == GroupWalk::self)
    walk_self_group<W, use>(in, group, sink);
  else
    walk_between_group<W, use>(in, group, sink);
}

// Groups of eight, compiled for AVX2 and called only where the CPU has it. Everything a group
// walk calls is inlined here (flatten), so that the 32-byte vectors of LeafLanes<8> are single
// AVX instructions and nothing compiled for AVX2 is shared with the rest of the program. AVX2
// brings no fused multiply-add (and -ffp-contract=off forbids contracting): the predicates
// round as everywhere else.
#if defined(__x86_64__) && defined(__GNUC__)
#define SNAG_HAVE_AVX2_WALK 1
template <GroupWalk kind, FilterUse use>
[[gnu::target("avx2"), gnu::flatten]] void walk_group_avx2(const WalkInput& in, int32_t group,
                                                           ThreadSink& sink) {
  walk_group<kind, 8, use>(in, group, sink);
}
#endif

bool cpu_has_avx2() {
#if defined(SNAG_HAVE_AVX2_WALK)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

class CpuBackend final : public Backend {
 public:
  CpuBackend(int threads, CpuWalkWidth width)
      : threads_(thread_count(threads)), wide_(cpu_walk_lanes(width) == 8), avx2_(cpu_has_avx2()) {}

  std::string_view name() const override { return "cpu"; }

  void set_topology(const Topology& topology) override {
    topology_ = &topology;
    trees_.assign(static_cast<size_t>(topology.part_count()), bvh::Tree{});
  }

  void set_part_positions(std::span<const geom::Vec3d> positions,
                          std::span<const uint8_t>) override {
    positions_ = positions;
  }

  DegeneracyScan scan_degenerate_parts(std::span<const int32_t> parts) override {
    const geom::FilteredPredicates pred{positions_.data()};
    DegeneracyScan scan;
    for (int32_t part : parts) {
      const int32_t begin = topology_->layout.triangle_begin[part];
      const int32_t end = topology_->layout.triangle_begin[part + 1];
      std::vector<uint8_t> answer(static_cast<size_t>(end - begin));
      for_each_index(threads_, end - begin, kSerialItems, [&](int64_t i) {
        const geom::Tri tri = topology_->triangles[begin + i];
        answer[i] = static_cast<uint8_t>(geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]));
      });
      for (int32_t t = begin; t < end; ++t) {
        if (answer[t - begin] == static_cast<uint8_t>(geom::Answer::yes))
          scan.degenerate.push_back(t);
        if (answer[t - begin] == static_cast<uint8_t>(geom::Answer::uncertain))
          scan.uncertain.push_back(t);
      }
    }
    std::sort(scan.degenerate.begin(), scan.degenerate.end());
    std::sort(scan.uncertain.begin(), scan.uncertain.end());
    return scan;
  }

  void build_part(int32_t part) override { trees_[part].build(part_view(part), threads_); }
  void refit_part(int32_t part) override { trees_[part].refit(part_view(part), threads_); }
  double part_quality(int32_t part) override { return trees_[part].quality(threads_); }

  FilteredFrame detect_checks(std::span<const int32_t> degenerate, FilterUse use,
                              std::span<const int32_t> checks) override {
    return use == FilterUse::certify ? detect_with<FilterUse::certify>(degenerate, checks)
                                     : detect_with<FilterUse::defer_all>(degenerate, checks);
  }

 protected:
  int32_t part_count() const override { return topology_ ? topology_->part_count() : 0; }
  int32_t check_count() const override {
    return topology_ ? static_cast<int32_t>(topology_->checks.size()) : 0;
  }

 private:
  template <FilterUse use>
  FilteredFrame detect_with(std::span<const int32_t> degenerate, std::span<const int32_t> checks) {
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
    // The planes of the parts the checks read.
    planes_.resize(static_cast<size_t>(n));
    if constexpr (use == FilterUse::certify) {
      std::vector<uint8_t> needed(static_cast<size_t>(topo.part_count()), 0);
      for (int32_t c : checks) needed[topo.checks[c].a] = needed[topo.checks[c].b] = 1;
      for (int32_t part = 0; part < topo.part_count(); ++part) {
        if (!needed[part]) continue;
        const int32_t begin = topo.layout.triangle_begin[part];
        const int32_t end = topo.layout.triangle_begin[part + 1];
        for_each_index(threads_, end - begin, kSerialItems, [&](int64_t i) {
          planes_[begin + i] = triangle_plane(positions_.data(), topo.triangles[begin + i]);
        });
      }
    }
    // The fans of the parts checked against themselves: their pairs' tests read them.
    if constexpr (use == FilterUse::certify) {
      fan_clear_.resize(static_cast<size_t>(topo.vertex_count));
      const FanView fans{topo.fan_begin.data(), topo.fan_steps.data()};
      for (int32_t c : checks) {
        if (!topo.checks[c].self()) continue;
        const int32_t part = topo.checks[c].a;
        const int32_t begin = topo.layout.vertex_begin[part];
        const int32_t end = topo.layout.vertex_begin[part + 1];
        for_each_index(threads_, end - begin, kSerialItems, [&](int64_t i) {
          const auto v = static_cast<int32_t>(begin + i);
          fan_clear_[v] = fan_is_clear(positions_.data(), planes_.data(), fans, v) ? 1 : 0;
        });
      }
    }
    const FrameView frame_view{positions_.data(), planes_.data(),
                               use == FilterUse::certify ? fan_clear_.data() : nullptr};

    std::vector<ThreadSink> sinks(static_cast<size_t>(threads_));
    for (int32_t c : checks) {
      const auto check_start = Clock::now();
      const PartCheck check = topo.checks[c];
      if (check.self())
        detect_self<use>(check.a, frame_view, view, degenerate_flags, sinks);
      else
        detect_between<use>(check.a, check.b, frame_view, view, degenerate_flags, sinks);
      frame.check_seconds.push_back(seconds_since(check_start));
    }

    std::vector<EdgeTriangleTask> hits;
    std::vector<FacePair> duplicates;
    size_t hit_count = 0;
    for (const ThreadSink& sink : sinks) hit_count += sink.hits.size();
    hits.reserve(hit_count);
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
    frame.pairs = expand_hits(topo, hits, degenerate_flags, threads_);
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

  /// A part against itself: its neighbour pairs from their list (their boxes overlap, but for a
  /// collapsed triangle's empty one: it is degenerate, so skipped here too),
  /// a triangle's pairs at a time, those of a triangle whose corners all have clear fans
  /// skipped whole (98% of a settled cloth's triangles), then the other candidates from its tree,
  /// the leaves in groups of 4 or 8 consecutive positions (walk_self_group), groups in leaf order;
  /// dynamic chunks because groups in dense regions cost more.
  template <FilterUse use>
  void detect_self(int32_t part, const FrameView& frame_view, const TopologyView& view,
                   const std::vector<uint8_t>& degenerate_flags, std::vector<ThreadSink>& sinks) {
    const Topology& topo = *topology_;
    const int32_t base = topo.layout.triangle_begin[part];
    if (topo.layout.triangle_begin[part + 1] == base) return;
    const WalkInput in{trees_[part].view(),    base, {}, 0, &frame_view, &view,
                       degenerate_flags.data()};
    const int32_t end = topo.layout.triangle_begin[part + 1];
    const bool any_degenerate =
        std::find(degenerate_flags.begin() + base, degenerate_flags.begin() + end, 1) !=
        degenerate_flags.begin() + end;
#pragma omp parallel num_threads(threads_)
    {
      ThreadSink& sink = sinks[static_cast<size_t>(omp_get_thread_num())];
#pragma omp for schedule(static) nowait
      for (int32_t t = base; t < end; ++t) {
        const int64_t first = topo.neighbor_begin[t], last = topo.neighbor_begin[t + 1];
        if (first == last) continue;
        // Every pair of t shares one of its corners: when all three have clear fans, no pair of
        // t can intersect. In a frame with no degenerate triangle all of them count as
        // candidates at once. (A clear fan's triangles have certified nonzero area, but under
        // `--exact off` the rounded scan may still flag one of them degenerate, and degenerate
        // triangles are no candidates: such frames count pair by pair, as the GPU does.)
        if (frame_view.fan_clear && !any_degenerate &&
            corners_clear(frame_view.fan_clear, topo.triangles[t])) {
          sink.candidates += last - first;
          continue;
        }
        for (int64_t i = first; i < last; ++i) {
          const int32_t x = topo.neighbor_pairs[i][1];
          if (degenerate_flags[t] || degenerate_flags[x]) continue;
          ++sink.candidates;
          const uint32_t shared = topo.neighbor_shared[i];
          test_pair<use>(frame_view, view, t, x, shared & 7u, shared >> 3, sink);
        }
      }
      walk_groups<GroupWalk::self, use>(in, sink);
    }
  }

  /// Two parts: the leaves of the larger one, in groups, each walk the other's whole tree
  /// (walk_between_group). The parts share no vertex, so there is no neighbour list.
  template <FilterUse use>
  void detect_between(int32_t a, int32_t b, const FrameView& frame_view, const TopologyView& view,
                      const std::vector<uint8_t>& degenerate_flags,
                      std::vector<ThreadSink>& sinks) {
    const Topology& topo = *topology_;
    auto size = [&](int32_t p) {
      return topo.layout.triangle_begin[p + 1] - topo.layout.triangle_begin[p];
    };
    if (size(a) == 0 || size(b) == 0) return;
    // Parts whose trees' roots are apart (most pairs of a scene of many objects) have no
    // candidate: every walk would stop at the other root. Left out before the parallel region
    // they would each open.
    if (!geom::overlap(trees_[a].boxes()[0], trees_[b].boxes()[0])) return;
    if (size(a) < size(b)) std::swap(a, b);
    const WalkInput in{trees_[a].view(),
                       topo.layout.triangle_begin[a],
                       trees_[b].view(),
                       topo.layout.triangle_begin[b],
                       &frame_view,
                       &view,
                       degenerate_flags.data()};
#pragma omp parallel num_threads(threads_)
    {
      ThreadSink& sink = sinks[static_cast<size_t>(omp_get_thread_num())];
      walk_groups<GroupWalk::between, use>(in, sink);
    }
  }

  /// Inside a parallel region: the `kind` walk of every group of in.tree at the chosen width
  /// (of 8 leaves through walk_group_avx2 where the CPU has AVX2), shared among the threads in
  /// dynamic chunks of 128 / W group parents (128 to 256 leaves).
  template <GroupWalk kind, FilterUse use>
  void walk_groups(const WalkInput& in, ThreadSink& sink) const {
    if (wide_)
      walk_groups_of<8, kind, use>(in, sink);
    else
      walk_groups_of<4, kind, use>(in, sink);
  }

  template <int W, GroupWalk kind, FilterUse use>
  void walk_groups_of(const WalkInput& in, ThreadSink& sink) const {
    int32_t first, last;
    bvh::group_range<W>(in.tree.shape, first, last);
#pragma omp for schedule(dynamic, 128 / W)
    for (int32_t node = first; node < last; ++node) {
      bvh::for_each_group_under<W>(in.tree.shape, node, [&](int32_t group) {
#if defined(SNAG_HAVE_AVX2_WALK)
        if constexpr (W == 8) {
          if (avx2_) {
            walk_group_avx2<kind, use>(in, group, sink);
            return;
          }
        }
#endif
        walk_group<kind, W, use>(in, group, sink);
      });
    }
  }

  /// Part p's triangles over the whole frame's positions: its tree's triangle ids are local.
  mesh::MeshView part_view(int32_t part) const {
    const int32_t begin = topology_->layout.triangle_begin[part];
    const int32_t end = topology_->layout.triangle_begin[part + 1];
    return {positions_.data(), topology_->triangles.data() + begin,
            static_cast<int32_t>(positions_.size()), end - begin};
  }

  int threads_;
  bool wide_;  ///< groups of 8 leaves, else 4
  bool avx2_;  ///< the CPU has AVX2: groups of 8 run walk_group_avx2
  const Topology* topology_ = nullptr;
  std::span<const geom::Vec3d> positions_;
  std::vector<geom::PlaneCoefficients> planes_;  ///< per triangle, this frame
  std::vector<uint8_t> fan_clear_;               ///< per vertex, this frame: fan_is_clear
  std::vector<bvh::Tree> trees_;                 ///< per part
};

}  // namespace

int cpu_walk_lanes(CpuWalkWidth width) {
  switch (width) {
    case CpuWalkWidth::four:
      return 4;
    case CpuWalkWidth::eight:
      return 8;
    case CpuWalkWidth::automatic:
      break;
  }
  return cpu_has_avx2() ? 8 : 4;
}

std::unique_ptr<Backend> make_cpu_backend(int threads, CpuWalkWidth width) {
  return std::make_unique<CpuBackend>(threads, width);
}

}  // namespace snag::detect
