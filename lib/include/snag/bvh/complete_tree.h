// The shape of the seed paper's tree: a complete binary tree stored breadth-first with one
// triangle per leaf. n leaves fix everything, so nothing but the boxes is stored:
//
//   node i has children 2i + 1 and 2i + 2, parent (i - 1) / 2; level l starts at 2^l - 1;
//   2n - 1 nodes; nodes 0 .. n - 2 are internal, n - 1 .. 2n - 2 are leaves.
//
// With D = floor(log2(2n - 1)) the deepest level, m = 2n - 2^D leaves sit on level D (they
// are the leftmost) and the other n - m on level D - 1. A leaf's *position* is its rank in
// left-to-right order, which is the order of the sorted triangles: positions 0 .. m - 1 are
// the level-D leaves, m .. n - 1 the level-(D - 1) ones.
//
// The leaves under node i (level l, offset o = i - (2^l - 1)) are the positions
// [f(o 2^(D-l)), f((o + 1) 2^(D-l))) with f(s) = s for s <= m and (s + m) / 2 above: s counts
// level-D slots, and past the m real ones each leaf of level D - 1 stands for two slots.
// That range is what the build splits at (the paper's Eq. 1).
#pragma once

#include <cstdint>

#include "snag/geom/hd.h"

namespace snag::bvh {

SNAG_HD_INLINE int floor_log2(uint32_t x) {
#if defined(__CUDA_ARCH__)
  return 31 - __clz(x);
#else
  return 31 - __builtin_clz(x);
#endif
}

/// Number of trailing zero bits; x != 0.
SNAG_HD_INLINE int count_trailing_zeros(uint32_t x) {
#if defined(__CUDA_ARCH__)
  return __ffs(static_cast<int>(x)) - 1;
#else
  return __builtin_ctz(x);
#endif
}

struct CompleteTree {
  int32_t leaf_count = 0;      ///< n >= 1, or 0 in the empty tree (CompleteTree())
  int32_t depth = 0;           ///< D, the deepest level
  int32_t deepest_leaves = 0;  ///< m = 2n - 2^D

  CompleteTree() = default;
  SNAG_HD explicit CompleteTree(int32_t n)
      : leaf_count(n),
        depth(floor_log2(static_cast<uint32_t>(2 * n - 1))),
        deepest_leaves(2 * n - (1 << floor_log2(static_cast<uint32_t>(2 * n - 1)))) {}

  /// 2n - 1; 0 for the empty tree (a part without triangles).
  SNAG_HD_INLINE int32_t node_count() const { return leaf_count > 0 ? 2 * leaf_count - 1 : 0; }
  SNAG_HD_INLINE int32_t first_leaf() const { return leaf_count - 1; }
  SNAG_HD_INLINE bool is_leaf(int32_t node) const { return node >= leaf_count - 1; }
  SNAG_HD_INLINE static int32_t level_of(int32_t node) {
    return floor_log2(static_cast<uint32_t>(node + 1));
  }
  SNAG_HD_INLINE static int32_t level_begin(int32_t level) { return (1 << level) - 1; }

  SNAG_HD_INLINE int32_t leaf_at(int32_t position) const {
    return position < deepest_leaves ? (1 << depth) - 1 + position
                                     : leaf_count - 1 + (position - deepest_leaves);
  }
  SNAG_HD_INLINE int32_t position_of(int32_t leaf) const {
    const int32_t deepest_begin = (1 << depth) - 1;
    return leaf >= deepest_begin ? leaf - deepest_begin : leaf - (leaf_count - 1) + deepest_leaves;
  }
  /// Leaf positions under `node`: [begin, end).
  SNAG_HD_INLINE void positions_under(int32_t node, int32_t& begin, int32_t& end) const {
    const int32_t level = level_of(node);
    const int64_t offset = node - level_begin(level);
    const int shift = depth - level;
    begin = slot_to_position(offset << shift);
    end = slot_to_position((offset + 1) << shift);
  }

 private:
  SNAG_HD_INLINE int32_t slot_to_position(int64_t slot) const {
    return static_cast<int32_t>(slot <= deepest_leaves ? slot : (slot + deepest_leaves) / 2);
  }
};

}  // namespace snag::bvh
