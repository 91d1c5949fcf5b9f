// The BVH over one mesh: boxes of the complete tree (complete_tree.h) and the permutation from
// leaf positions to triangles. Memory: 24 bytes per node (a float box, rounded outward) for
// 2n - 1 nodes, plus 4 bytes per triangle for the permutation (and, on the host, 4 for its
// inverse): about 52 (56) bytes per triangle.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "snag/bvh/complete_tree.h"
#include "snag/geom/box.h"
#include "snag/geom/hd.h"
#include "snag/mesh/mesh.h"

namespace snag::bvh {

/// Non-owning view, passed by value into kernels and OpenMP loops.
struct TreeView {
  CompleteTree shape;
  geom::Box3f* boxes = nullptr;          ///< 2n - 1, breadth-first
  const int32_t* triangle_at = nullptr;  ///< n: the triangle of each leaf position
};

/// The leaf box of a triangle with corners a, b and c, on both backends: their box, or the empty
/// box when two corners coincide. Without it, a pile of such triangles at one point (a frame
/// whose vertices were all zeroed, a region collapsed by a simulation gone wrong) made the walks
/// quadratic: 200,000 of them took 11 s on two cores, now 0.4. The walks find candidates by
/// overlapping boxes, and an empty box overlaps nothing but boxes reaching +-FLT_MAX on every
/// axis; so such a triangle must be one that every frame's degenerate scan certainly lists (the
/// filtered orient2d certifies the zeros of coincident points), which the pair tests leave out
/// anyway, their degenerate flags still guarding them. Collinear corners that are distinct keep
/// their box: telling them needs an exact predicate, and they do not pile up.
SNAG_HD_INLINE geom::Box3f leaf_box(geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) {
  const bool collapsed = (a == b) | (b == c) | (c == a);
  return collapsed ? geom::empty_box() : geom::triangle_box(a, b, c);
}

/// Box of internal node `node` from its children's (already refit) boxes.
SNAG_HD_INLINE void refit_internal(int32_t node, TreeView tree) {
  tree.boxes[node] = geom::merge(tree.boxes[2 * node + 1], tree.boxes[2 * node + 2]);
}

/// The first node of the level below `node`'s (2^31 - 1 under a node of level 30, the deepest a
/// tree of int32 nodes has).
SNAG_HD_INLINE int32_t level_end(int32_t node) {
  return static_cast<int32_t>((2u << CompleteTree::level_of(node)) - 1u);
}

/// Where walk_subtree goes from node i: its left child `left` when i is `internal` and
/// overlaps, else `skip`, the next subtree in depth-first order; `last` when there is none
/// under the walk's root.
struct WalkStep {
  int32_t left, skip;
  bool internal, last;
};

/// `below_root` is the first node of the level under the walk's root: a next subtree that
/// starts before it is at the root's level or above, so outside the root's subtree.
SNAG_HD_INLINE WalkStep walk_step(int32_t i, int32_t first_leaf, int32_t below_root) {
  const uint32_t j = static_cast<uint32_t>(i) + 1;
  const auto skip = static_cast<int32_t>(j >> count_trailing_zeros(~j));
  return {2 * i + 1, skip, i < first_leaf, skip < below_root};
}

/// Walks the subtree under `root` depth-first without a stack: test(node) says whether a
/// node's box overlaps what is searched for; at an overlapping leaf, at_leaf(leaf) is called.
/// Memory: a few registers.
///
/// The walk's next node is chosen without a data-dependent branch: the left child when the
/// box overlaps an internal node, else the next subtree in depth-first order. In 1-based
/// numbering j = i + 1, left children are even and the parent of j is j >> 1, so climbing out
/// of t right children and stepping to the sibling is (j >> t) + 1 in 1-based terms, (j >> t)
/// in 0-based ones, with t the number of trailing ones of j. The walk ends when that climb
/// would reach the subtree's root: when the next subtree's level (that of 0-based node s is
/// floor(log2(s + 1))) is not below the root's, which is s < level_end(root).
template <class Test, class AtLeaf>
SNAG_HD_INLINE void walk_subtree(const TreeView& tree, int32_t root, Test&& test,
                                 AtLeaf&& at_leaf) {
  const int32_t first_leaf = tree.shape.leaf_count - 1;
  const int32_t below_root = level_end(root);
  int32_t i = root;
  while (true) {
    const bool hit = test(i);
    const WalkStep step = walk_step(i, first_leaf, below_root);
    if (hit & !step.internal) at_leaf(i);
    const bool descend = hit & step.internal;
    if (!descend & step.last) break;
    i = descend ? step.left : step.skip;
  }
}

/// walk_subtree with the boxes read one step ahead: overlaps(box) tests a node's box, and both
/// possible successors' boxes are read before the current one is tested, so that the read
/// leaves the step's chain of dependent instructions. On a GPU, where a walk is that chain and
/// little else hides it, this took the 36K walk from 77 to 69 us. Same nodes, same order.
///
/// Nodes from index `first_unopened` on are not opened: one that overlaps goes to at_leaf as a
/// leaf does (the default opens every internal node). Since a level's nodes are consecutive,
/// level_begin(L) stops the walk at level L (split_walk_level).
template <class Overlaps, class AtLeaf>
SNAG_HD_INLINE void walk_subtree_read_ahead(const TreeView& tree, int32_t root, Overlaps&& overlaps,
                                            AtLeaf&& at_leaf, int32_t first_unopened = INT32_MAX) {
  const int32_t first_leaf =
      tree.shape.leaf_count - 1 < first_unopened ? tree.shape.leaf_count - 1 : first_unopened;
  const int32_t below_root = level_end(root);
  int32_t i = root;
  geom::Box3f box = tree.boxes[root];
  while (true) {
    const WalkStep step = walk_step(i, first_leaf, below_root);
    // A successor that does not exist reads node i again (in cache) rather than branching.
    const geom::Box3f left_box = tree.boxes[step.internal ? step.left : i];
    const geom::Box3f skip_box = tree.boxes[step.last ? i : step.skip];
    const bool hit = overlaps(box);
    if (hit & !step.internal) at_leaf(i);
    const bool descend = hit & step.internal;
    if (!descend & step.last) break;
    i = descend ? step.left : step.skip;
    box = descend ? left_box : skip_box;
  }
}

/// Calls visit(leaf) with the node index of every leaf under `node` (itself, when it is one)
/// whose box overlaps `box`; with `first_unopened`, also each overlapping node the walk does
/// not open (walk_subtree_read_ahead).
template <class Visit>
SNAG_HD_INLINE void for_each_overlapping_leaf_under(TreeView tree, int32_t node,
                                                    const geom::Box3f& box, Visit&& visit,
                                                    int32_t first_unopened = INT32_MAX) {
  walk_subtree_read_ahead(
      tree, node, [&](const geom::Box3f& other) { return geom::overlap(box, other); }, visit,
      first_unopened);
}

/// Calls visit(leaf) with the node index of every leaf after `position` (in leaf order) whose
/// box overlaps the leaf at `position`, so that each unordered pair of leaves is visited once,
/// from the earlier one. For every ancestor reached from a left child, the right sibling's
/// subtree holds exactly the later leaves under that ancestor; each is walked
/// (walk_subtree_read_ahead). Nothing but boxes is read.
///
/// With `first_unopened` (see walk_subtree_read_ahead), the walks stop there: visit(node) also
/// gets each overlapping node they do not open, and the later overlapping leaves are then
/// those visited plus, under each such internal node, those for_each_overlapping_leaf_under
/// finds.
template <class Visit>
SNAG_HD_INLINE void for_each_later_overlapping_leaf(TreeView tree, int32_t position, Visit&& visit,
                                                    int32_t first_unopened = INT32_MAX) {
  const int32_t leaf = tree.shape.leaf_at(position);
  const geom::Box3f box = tree.boxes[leaf];
  for (int32_t node = leaf; node > 0; node = (node - 1) >> 1) {
    if (!(node & 1)) continue;  // a right child: nothing later under its parent's other side
    for_each_overlapping_leaf_under(tree, node + 1, box, visit, first_unopened);
  }
}

/// Up to this many nodes at the split level (split_walk_level), the GPU walks above that level
/// a warp per node, testing the level's nodes all against all (2M box tests at most); above it,
/// a thread per leaf.
inline constexpr int32_t kSplitWarpNodes = 2048;
/// The deepest level with at most kSplitWarpNodes nodes.
inline constexpr int32_t kSplitWarpLevel =
    std::bit_width(static_cast<uint32_t>(kSplitWarpNodes)) - 1;

/// The level at which a GPU splits each leaf's walk in two (the walks above it, then one
/// walk under each overlapping node of it): five levels above the deepest (nodes of 16 to 32
/// leaves) while that level has at most kSplitWarpNodes nodes (trees of up to 65,536 leaves),
/// else six (32 to 64 leaves). Five levels gave a settled 36K cloth frame (depth 16) 0.131 ->
/// 0.128 ms on an H200, and 2,244 triangles 0.081-0.082 -> 0.076-0.078, where cloth-ball (depth
/// 17) at five would have 4,096 nodes there and walk a thread per leaf, 7% slower
/// (cuda/NOTES.md).
SNAG_HD_INLINE int32_t split_walk_level(const CompleteTree& shape) {
  if (shape.depth <= 5) return 0;
  return shape.depth - (shape.depth - 5 <= kSplitWarpLevel ? 5 : 6);
}

/// The nodes of level `level`: [first, first + count), 2^level of them (levels 0 to D - 1 are
/// full, the split level among them).
struct LevelNodes {
  int32_t first = 0;
  int32_t count = 0;
};

SNAG_HD_INLINE LevelNodes level_nodes(int32_t level) {
  return {CompleteTree::level_begin(level), int32_t{1} << level};
}

/// At most this many levels lie between a leaf and its ancestor on the split level.
inline constexpr int kLevelsUnderSplit = 6;

/// The part of for_each_later_overlapping_leaf(tree, position, visit, first_unopened) that lies
/// under the leaf's own node of the split level, first_unopened being that level's first node
/// `split_first`: for each node on the path from `leaf` (the leaf's node index, `box` its box)
/// up to (not including) that level that is a left child, its right sibling, handed over whole
/// when its box overlaps the leaf's. Calls step(hand, sibling) exactly kLevelsUnderSplit times,
/// `hand` false for a step that hands nothing over (a right child, a sibling that misses, or a
/// step past the climb's end), so that the lanes of a warp can take the steps side by side,
/// each a warp-wide call; a `leaf` of 0 (the root) hands nothing over. The rest of what that
/// walk hands over is every later node of the split level whose box overlaps the leaf's: the
/// GPU finds those by testing every later node of the level against the leaf's own node of
/// that level, a warp per node, then against the leaf. That node's box holds the leaf's (every
/// box is its children's merged exactly), so a node that misses it misses the leaf, as the
/// walk's own pruning assumes.
template <class Step>
SNAG_HD_INLINE void climb_under_split(TreeView tree, int32_t leaf, const geom::Box3f& box,
                                      int32_t split_first, Step&& step) {
  const int32_t below = 2 * split_first + 1;  // the first node of the level under it
  int32_t node = leaf;
  for (int level = 0; level < kLevelsUnderSplit; ++level) {
    const bool climbing = node >= below;
    step(climbing && (node & 1) && geom::overlap(box, tree.boxes[node + 1]), node + 1);
    if (climbing) node = (node - 1) >> 1;
  }
}

/// for_each_later_overlapping_leaf, calling visit(triangle) with the leaf's triangle.
template <class Visit>
SNAG_HD_INLINE void for_each_later_overlap(TreeView tree, int32_t position, Visit&& visit) {
  for_each_later_overlapping_leaf(
      tree, position, [&](int32_t leaf) { visit(tree.triangle_at[tree.shape.position_of(leaf)]); });
}

/// Calls visit(leaf) with the node index of every leaf of `tree` whose box overlaps `box`: a
/// query from another tree's leaf (two objects checked against each other).
/// With `first_unopened`, visit also gets the overlapping nodes not opened, as in
/// for_each_later_overlapping_leaf.
template <class Visit>
SNAG_HD_INLINE void for_each_overlapping_leaf(TreeView tree, const geom::Box3f& box, Visit&& visit,
                                              int32_t first_unopened = INT32_MAX) {
  for_each_overlapping_leaf_under(tree, 0, box, visit, first_unopened);
}

/// The tree-quality sum in one fixed order that both backends reproduce bit for bit and the
/// GPU runs in parallel: the internal nodes' half areas in blocks of kQualityBlock consecutive
/// nodes; in each block, kQualityLanes partial sums, lane k adding the block's nodes k, k +
/// kQualityLanes, k + 2 kQualityLanes, ... in order, then the partial sums in lane order; then
/// the block sums in order (quality_from_blocks). The GPU gives a block's lanes to the threads
/// of one warp: two chains of 32 additions where one sum in node order was a chain of 1024
/// (10.9 us at 36K triangles, most of the kernel).
constexpr int32_t kQualityBlock = 1024;
constexpr int32_t kQualityLanes = 32;

SNAG_HD_INLINE int32_t quality_block_count(const CompleteTree& shape) {
  return (shape.leaf_count - 1 + kQualityBlock - 1) / kQualityBlock;
}

/// Internal nodes of block `block`: [begin, begin + count).
SNAG_HD_INLINE int32_t quality_block_size(const CompleteTree& shape, int32_t block) {
  const int32_t begin = block * kQualityBlock, internal = shape.leaf_count - 1;
  return begin + kQualityBlock < internal ? kQualityBlock : internal - begin;
}

/// Lane `lane`'s partial sum of a block of `count` nodes whose k-th half area is area(k).
template <class Area>
SNAG_HD_INLINE double quality_lane_sum(Area&& area, int32_t count, int32_t lane) {
  double sum = 0.0;
  for (int32_t k = lane; k < count; k += kQualityLanes) sum += area(k);
  return sum;
}

/// The sum of block `block`'s internal-node half areas.
SNAG_HD_INLINE double quality_block_sum(const geom::Box3f* boxes, const CompleteTree& shape,
                                        int32_t block) {
  const geom::Box3f* first = boxes + block * kQualityBlock;
  const int32_t count = quality_block_size(shape, block);
  double sum = 0.0;
  for (int32_t lane = 0; lane < kQualityLanes; ++lane)
    sum += quality_lane_sum([&](int32_t k) { return geom::half_area(first[k]); }, count, lane);
  return sum;
}

/// Quality from the block sums: their sum, in order, over the root's half area (0 without an
/// internal node or for a root of zero area).
SNAG_HD_INLINE double quality_from_blocks(const double* block_sums, int32_t blocks,
                                          const geom::Box3f& root) {
  double sum = 0.0;
  for (int32_t block = 0; block < blocks; ++block) sum += block_sums[block];
  const double root_area = geom::half_area(root);
  return blocks > 0 && root_area > 0.0 ? sum / root_area : 0.0;
}

/// What a leaf's box bounds.
enum class LeafBoxes {
  /// leaf_box: a triangle with two coincident corners gets the empty box. For the pair search,
  /// which leaves such triangles out (the CUDA backend's trees are always of this kind).
  skip_collapsed,
  /// geom::triangle_box: every triangle, a collapsed one included (a point or a segment is still
  /// on the surface). For distance queries (measure::PenetrationMeter).
  every_triangle,
};

/// Owning tree on the host (the CPU backend; the CUDA backend keeps device buffers instead).
class Tree {
 public:
  explicit Tree(LeafBoxes leaf_boxes = LeafBoxes::skip_collapsed) : leaf_boxes_(leaf_boxes) {}

  /// Builds the paper's tree: sort the centroids of each segment along the longest axis of
  /// their bounds and split at the count the complete shape dictates, level by level, all
  /// segments of a level in parallel. Ties are broken by triangle id, so the tree is the same
  /// for every thread count. Then refits.
  void build(mesh::MeshView mesh, int threads);
  /// Recomputes every box from the current positions, leaves first, then one level at a
  /// time up to the root, each large level in parallel (the top levels' few thousand nodes in
  /// one loop on the calling thread).
  void refit(mesh::MeshView mesh, int threads);
  /// Sum of internal-node half areas over the root's half area (0 for a single leaf), summed
  /// in the blocked order of quality_block_sum / quality_from_blocks, so the same bits for
  /// every thread count.
  double quality(int threads = 1) const;

  TreeView view() { return {shape_, boxes_.data(), triangle_at_.data()}; }
  const CompleteTree& shape() const { return shape_; }
  const std::vector<geom::Box3f>& boxes() const { return boxes_; }
  const std::vector<int32_t>& triangle_at() const { return triangle_at_; }

 private:
  CompleteTree shape_;
  std::vector<geom::Box3f> boxes_;
  std::vector<int32_t> triangle_at_;
  std::vector<int32_t> leaf_of_triangle_;  ///< the inverse of triangle_at_: each triangle's leaf
  LeafBoxes leaf_boxes_;
};

}  // namespace snag::bvh
