// The BVH over one mesh: boxes of the complete tree (complete_tree.h) and the permutation from
// leaf positions to triangles. Memory: 24 bytes per node (a float box, rounded outward) for
// 2n - 1 nodes, plus 4 bytes per triangle for the permutation: about 52 bytes per triangle.
#pragma once

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
  geom::Box3f* boxes = nullptr;             ///< 2n - 1, breadth-first
  const int32_t* triangle_at = nullptr;     ///< n: the triangle of each leaf position
};

/// Box of leaf `leaf` from its triangle's current corners.
SNAG_HD_INLINE void refit_leaf(int32_t leaf, TreeView tree, mesh::MeshView mesh) {
  const geom::Tri t = mesh.triangles[tree.triangle_at[tree.shape.position_of(leaf)]];
  tree.boxes[leaf] = geom::triangle_box(mesh.positions[t.v[0]], mesh.positions[t.v[1]], mesh.positions[t.v[2]]);
}

/// Box of internal node `node` from its children's (already refit) boxes.
SNAG_HD_INLINE void refit_internal(int32_t node, TreeView tree) {
  tree.boxes[node] = geom::merge(tree.boxes[2 * node + 1], tree.boxes[2 * node + 2]);
}

/// Calls visit(triangle) for every leaf after `position` (in leaf order) whose box overlaps
/// the leaf at `position`, so that each unordered pair of leaves is visited once, from the
/// earlier one. For every ancestor reached from a left child, the right sibling's subtree holds
/// exactly the later leaves under that ancestor; each is walked depth-first without a stack:
/// the next node after i is i + 1 when i is a left child (odd), else the next after its parent,
/// and the walk ends on climbing back to the subtree's root. Memory: a few registers.
template <class Visit>
SNAG_HD_INLINE void for_each_later_overlap(TreeView tree, int32_t position, Visit&& visit) {
  const CompleteTree shape = tree.shape;
  const int32_t leaf = shape.leaf_at(position);
  const geom::Box3f box = tree.boxes[leaf];
  for (int32_t node = leaf; node > 0; node = (node - 1) >> 1) {
    if (!(node & 1)) continue;  // a right child: nothing later under its parent's other side
    const int32_t root = node + 1;
    int32_t i = root;
    while (true) {
      if (geom::overlap(box, tree.boxes[i])) {
        if (!shape.is_leaf(i)) {
          i = 2 * i + 1;
          continue;
        }
        visit(tree.triangle_at[shape.position_of(i)]);
      }
      // Advance to the next subtree in depth-first order, or stop at the root.
      while (i != root && !(i & 1)) i = (i - 1) >> 1;
      if (i == root) break;
      ++i;
    }
  }
}

/// Owning tree on the host (the CPU backend; the CUDA backend keeps device buffers instead).
class Tree {
 public:
  /// Builds the paper's tree: sort the centroids of each segment along the longest axis of
  /// their bounds and split at the count the complete shape dictates, level by level, all
  /// segments of a level in parallel. Ties are broken by triangle id, so the tree is the same
  /// for every thread count. Then refits.
  void build(mesh::MeshView mesh, int threads);
  /// Recomputes every box from the current positions, leaves first, then one level at a
  /// time up to the root, each level in parallel.
  void refit(mesh::MeshView mesh, int threads);
  /// Sum of internal-node half areas over the root's half area (0 for a single leaf).
  double quality() const;

  TreeView view() { return {shape_, boxes_.data(), triangle_at_.data()}; }
  const CompleteTree& shape() const { return shape_; }
  const std::vector<geom::Box3f>& boxes() const { return boxes_; }
  const std::vector<int32_t>& triangle_at() const { return triangle_at_; }

 private:
  CompleteTree shape_;
  std::vector<geom::Box3f> boxes_;
  std::vector<int32_t> triangle_at_;
};

}  // namespace snag::bvh
