#include "snag/bvh/tree.h"

#include <algorithm>
#include <numeric>

#include "snag/threads.h"

namespace snag::bvh {

namespace {

/// Loops of at most this many leaves or nodes (and the quality's blocks of as many) run on one
/// thread (for_each_index): splitting them costs more than it saves.
constexpr int32_t kParallelLevel = 4096;

/// The internal nodes of `level`: [first, last).
void internal_nodes_of_level(const CompleteTree& shape, int32_t level, int32_t& first,
                             int32_t& last) {
  first = CompleteTree::level_begin(level);
  last = std::min(CompleteTree::level_begin(level + 1), shape.leaf_count - 1);
}

}  // namespace

void Tree::build(mesh::MeshView mesh, int threads) {
  const int32_t n = mesh.triangle_count;
  // A part without triangles (an obstacle file with none) has an empty tree: no nodes.
  shape_ = n > 0 ? CompleteTree(n) : CompleteTree();
  boxes_.assign(static_cast<size_t>(shape_.node_count()), geom::empty_box());
  triangle_at_.resize(static_cast<size_t>(n));
  std::iota(triangle_at_.begin(), triangle_at_.end(), 0);

  // Centroids times three (the sum of the corners): the order is the same and no division.
  std::vector<geom::Vec3d> centroid(static_cast<size_t>(n));
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int32_t t = 0; t < n; ++t) {
    const geom::Tri tri = mesh.triangles[t];
    centroid[t] = mesh.positions[tri.v[0]] + mesh.positions[tri.v[1]] + mesh.positions[tri.v[2]];
  }

  // Level by level: the segments of one level are disjoint ranges of triangle_at_.
  for (int32_t level = 0; level < shape_.depth; ++level) {
    int32_t first, last;
    internal_nodes_of_level(shape_, level, first, last);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (last - first > 1)
    for (int32_t node = first; node < last; ++node) {
      int32_t begin, end, left_begin, split;
      shape_.positions_under(node, begin, end);
      shape_.positions_under(2 * node + 1, left_begin, split);
      double lo[3] = {centroid[triangle_at_[begin]].x, centroid[triangle_at_[begin]].y,
                      centroid[triangle_at_[begin]].z};
      double hi[3] = {lo[0], lo[1], lo[2]};
      for (int32_t p = begin + 1; p < end; ++p) {
        const geom::Vec3d c = centroid[triangle_at_[p]];
        lo[0] = std::min(lo[0], c.x), hi[0] = std::max(hi[0], c.x);
        lo[1] = std::min(lo[1], c.y), hi[1] = std::max(hi[1], c.y);
        lo[2] = std::min(lo[2], c.z), hi[2] = std::max(hi[2], c.z);
      }
      const double extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
      const int axis =
          (extent[0] >= extent[1] && extent[0] >= extent[2]) ? 0 : (extent[1] >= extent[2] ? 1 : 2);
      auto* data = triangle_at_.data();
      std::nth_element(data + begin, data + split, data + end, [&](int32_t a, int32_t b) {
        const double ca = geom::coord(centroid[a], axis), cb = geom::coord(centroid[b], axis);
        return ca < cb || (ca == cb && a < b);
      });
    }
  }
  leaf_of_triangle_.resize(static_cast<size_t>(n));
  for (int32_t p = 0; p < n; ++p) leaf_of_triangle_[triangle_at_[p]] = shape_.leaf_at(p);
  refit(mesh, threads);
}

void Tree::refit(mesh::MeshView mesh, int threads) {
  TreeView tree = view();
  const int32_t n = shape_.leaf_count;
  // Leaves in triangle order: the corners are read in file order (mostly sequential) and
  // only the box writes scatter, where leaf order would scatter every read.
  auto fit_leaves = [&](auto&& box_of) {
    for_each_index(threads, n, kParallelLevel, [&](int64_t t) {
      const geom::Tri tri = mesh.triangles[t];
      tree.boxes[leaf_of_triangle_[t]] =
          box_of(mesh.positions[tri.v[0]], mesh.positions[tri.v[1]], mesh.positions[tri.v[2]]);
    });
  };
  // Lambdas, not the functions themselves: each has a type of its own, so each loop is compiled
  // with its box inlined. Both functions have one type, so passing them shared one loop that
  // called the box through a pointer, leaf by leaf (a 36K frame's refit 0.30 -> 0.69 ms).
  if (leaf_boxes_ == LeafBoxes::skip_collapsed)
    fit_leaves([](geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) { return leaf_box(a, b, c); });
  else
    fit_leaves(
        [](geom::Vec3d a, geom::Vec3d b, geom::Vec3d c) { return geom::triangle_box(a, b, c); });
  // One level at a time from the deepest internal level up, each level in parallel; the end
  // of each loop orders a level's writes before its parents read them. Levels too small to gain
  // from threads run on one, without a barrier or a parallel region (barriers are what costs
  // when the machine is shared and threads get descheduled); once at most kParallelLevel
  // internal nodes are left (the levels from the root down to this one), they all run in one
  // loop down the node ids, children always coming after their parent.
  for (int32_t level = shape_.depth - 1; level >= 0; --level) {
    int32_t first, last;
    internal_nodes_of_level(shape_, level, first, last);
    if (last <= kParallelLevel) {
      for (int32_t node = last - 1; node >= 0; --node) refit_internal(node, tree);
      break;
    }
    for_each_index(threads, last - first, kParallelLevel,
                   [&](int64_t i) { refit_internal(first + static_cast<int32_t>(i), tree); });
  }
}

double Tree::quality(int threads) const {
  const int32_t blocks = quality_block_count(shape_);
  if (blocks == 0) return 0.0;
  std::vector<double> block_sums(static_cast<size_t>(blocks));
  for_each_index(threads, blocks, kParallelLevel / kQualityBlock, [&](int64_t block) {
    block_sums[block] = quality_block_sum(boxes_.data(), shape_, static_cast<int32_t>(block));
  });
  return quality_from_blocks(block_sums.data(), blocks, boxes_[0]);
}

}  // namespace snag::bvh
