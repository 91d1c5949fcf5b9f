// The CPU's walks over the tree (tree.h) in groups: the W consecutive leaves under one node near
// the bottom of the tree walk it together, one SIMD lane each, as a GPU warp runs its leaves
// together. A step tests one node's box against every lane's box at once, so a group's walk
// costs about what one leaf's walk does while it finds the overlaps of W leaves.
//
// W is 4 (16-byte vectors, every x86-64 CPU) or 8 (32-byte vectors: one AVX instruction per
// compare when the caller is compiled for AVX2, see cpu_backend.cpp; without AVX the compiler
// splits each compare in two and the walk is several times slower than with W = 4). Host only.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "snag/bvh/complete_tree.h"
#include "snag/bvh/tree.h"
#include "snag/geom/box.h"

namespace snag::bvh {

/// log2 of the group width W (4 or 8).
template <int W>
constexpr int kGroupShift = W == 8 ? 3 : 2;

/// The level of the nodes that hold the groups of W leaves: D - log2(W) - 1 (the root for a
/// tree of fewer levels). A node there holds W to 2W leaves: exactly W when all of them are on
/// level D - 1, and then it is one group; otherwise each of its two children (W / 2 to W
/// leaves) is one (for_each_group_under). Groups on a single level would be half empty where
/// most leaves are on level D - 1 (a 36K-leaf tree's groups of 8 held 4.4 leaves on average;
/// these hold 8), and a walk costs about the same for a full group as for a half-empty one.
template <int W>
inline int32_t group_parent_level(const CompleteTree& shape) {
  return shape.depth > kGroupShift<W> ? shape.depth - kGroupShift<W> - 1 : 0;
}

/// The nodes of group_parent_level<W>(): [first, last), in leaf order.
template <int W>
inline void group_range(const CompleteTree& shape, int32_t& first, int32_t& last) {
  const int32_t level = group_parent_level<W>(shape);
  first = CompleteTree::level_begin(level);
  last = std::min(CompleteTree::level_begin(level + 1), shape.node_count());
}

/// Calls f(group) for the groups of W leaves under `node` of group_range<W>(), in leaf order:
/// the node itself when it holds at most W leaves, else its two children. Every leaf is in
/// exactly one group, and the groups of all such nodes, in order, cover the leaves in order.
template <int W, class F>
inline void for_each_group_under(const CompleteTree& shape, int32_t node, F&& f) {
  int32_t begin, end;
  shape.positions_under(node, begin, end);
  if (end - begin <= W) {
    f(node);
  } else {
    f(2 * node + 1);
    f(2 * node + 2);
  }
}

/// Bit i set for each lane i of `mask` that is set (a vector whose lanes of 4 or 8 bytes are all
/// ones or all zeros), from the sign bits of each 16-byte piece: one instruction each, where a
/// lane-by-lane extraction was a third of the walk's time.
template <class Mask>
inline uint32_t lane_bits(const Mask& mask) {
  constexpr int kLaneBytes = sizeof(mask[0]);
  static_assert(kLaneBytes == 4 || kLaneBytes == 8, "lanes of 4 or 8 bytes");
  uint32_t out = 0;
#if defined(__SSE2__)
  for (int piece = 0; piece < static_cast<int>(sizeof(Mask)) / 16; ++piece) {
    const char* bytes = reinterpret_cast<const char*>(&mask) + 16 * piece;
    uint32_t piece_bits;
    if constexpr (kLaneBytes == 4) {
      __m128 lanes;
      std::memcpy(&lanes, bytes, sizeof lanes);
      piece_bits = static_cast<uint32_t>(_mm_movemask_ps(lanes));
    } else {
      __m128d lanes;
      std::memcpy(&lanes, bytes, sizeof lanes);
      piece_bits = static_cast<uint32_t>(_mm_movemask_pd(lanes));
    }
    out |= piece_bits << (16 / kLaneBytes * piece);
  }
#else
  for (int lane = 0; lane < static_cast<int>(sizeof(Mask)) / kLaneBytes; ++lane)
    out |= static_cast<uint32_t>(mask[lane] & 1) << lane;
#endif
  return out;
}

/// W floats and W int32 as one vector each (explicit sizes: GCC ignores a vector_size that
/// depends on a template parameter).
template <int W>
struct LaneVectors;
template <>
struct LaneVectors<4> {
  typedef float Floats __attribute__((vector_size(16)));
  typedef int32_t Ints __attribute__((vector_size(16)));
};
template <>
struct LaneVectors<8> {
  typedef float Floats __attribute__((vector_size(32)));
  typedef int32_t Ints __attribute__((vector_size(32)));
};

/// The (up to W) leaves under node `group` (for_each_group_under) as SIMD lanes: their boxes and
/// triangles. Absent lanes get an empty box and are masked out.
template <int W>
struct LeafLanes {
  static_assert(W == 4 || W == 8, "groups of 4 or 8 leaves");
  using Lanes = typename LaneVectors<W>::Floats;
  using Mask = typename LaneVectors<W>::Ints;
  Lanes lo[3], hi[3];
  Mask present;
  int32_t triangle[W];
  int32_t leaf[W];
  int32_t members = 0;  ///< W / 2 .. W (fewer when the whole tree is that small)

  LeafLanes(const TreeView& tree, int32_t group) {
    int32_t begin, end;
    tree.shape.positions_under(group, begin, end);
    members = end - begin;
    for (int lane = 0; lane < W; ++lane) {
      geom::Box3f box = geom::empty_box();
      triangle[lane] = leaf[lane] = -1;
      if (lane < members) {
        leaf[lane] = tree.shape.leaf_at(begin + lane);
        box = tree.boxes[leaf[lane]];
        triangle[lane] = tree.triangle_at[begin + lane];
      }
      for (int k = 0; k < 3; ++k) {
        lo[k][lane] = box.lo[k];
        hi[k][lane] = box.hi[k];
      }
      // The empty box is not enough: a leaf box that reaches +-FLT_MAX on every axis
      // (coordinates beyond the float range) overlaps it.
      present[lane] = lane < members ? -1 : 0;
    }
  }

  /// A bit per lane whose box overlaps `box`. (Vectors are passed by reference and never
  /// returned: a 32-byte vector in a call would have another ABI with AVX than without.)
  uint32_t overlaps(const geom::Box3f& box) const {
    const Mask mask = (lo[0] <= box.hi[0]) & (hi[0] >= box.lo[0]) & (lo[1] <= box.hi[1]) &
                      (hi[1] >= box.lo[1]) & (lo[2] <= box.hi[2]) & (hi[2] >= box.lo[2]) & present;
    return bits(mask);
  }

  /// Bit `lane` of the result set for each lane whose mask is set (all ones): lane_bits.
  static uint32_t bits(const Mask& mask) { return lane_bits(mask); }

  /// Walks `tree`'s subtree under `root` for all lanes at once (walk_subtree), descending where
  /// any lane overlaps; at a leaf, calls visit_leaf(lane_bits, leaf's triangle) with a bit per
  /// lane that overlaps it (at least one).
  template <class VisitLeaf>
  void walk_leaves(const TreeView& tree, int32_t root, VisitLeaf&& visit_leaf) const {
    uint32_t last = 0;
    walk_subtree(
        tree, root,
        [&](int32_t i) {
          last = overlaps(tree.boxes[i]);
          return last != 0;
        },
        [&](int32_t i) { visit_leaf(last, tree.triangle_at[tree.shape.position_of(i)]); });
  }

  /// A visit_leaf for walk_leaves and for_each_later that calls visit(lane triangle, leaf's
  /// triangle) for each lane in its bits.
  template <class Visit>
  auto each_lane(Visit& visit) const {
    return [this, &visit](uint32_t lanes, int32_t other) {
      for (; lanes; lanes &= lanes - 1) visit(triangle[count_trailing_zeros(lanes)], other);
    };
  }

  /// The query of for_each_later_overlap for every member at once (this group's node is
  /// `group`): calls visit_leaf(lane_bits, other_triangle) for every later leaf, with a bit for
  /// each member whose box overlaps it, so that each unordered pair is visited once. Pairs of
  /// members come first, as (bits of the earlier members, later member's triangle).
  template <class VisitLeaf>
  void for_each_later(const TreeView& tree, int32_t group, VisitLeaf&& visit_leaf) const {
    for (int b = 1; b < members; ++b)
      if (const uint32_t earlier = overlaps(tree.boxes[leaf[b]]) & ((1u << b) - 1u))
        visit_leaf(earlier, triangle[b]);
    // Members against the later subtrees: the right siblings of the group's left-child
    // ancestors.
    for (int32_t node = group; node > 0; node = (node - 1) >> 1)
      if (node & 1) walk_leaves(tree, node + 1, visit_leaf);
  }
};

/// The per-leaf query of for_each_later_overlap, run for the (up to W) leaves under node
/// `group` (for_each_group_under) at once: calls visit(member_triangle, other_triangle) for every
/// pair of a member and a later leaf whose boxes overlap, each unordered pair once. The members
/// share every ancestor above the group, so their walks through the later subtrees are one walk
/// (LeafLanes::for_each_later). Memory: a few registers and the W boxes.
template <int W, class Visit>
inline void for_each_later_overlap_grouped(TreeView tree, int32_t group, Visit&& visit) {
  const LeafLanes<W> lanes(tree, group);
  lanes.for_each_later(tree, group, lanes.each_lane(visit));
}

}  // namespace snag::bvh
