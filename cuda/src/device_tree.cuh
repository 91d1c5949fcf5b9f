// The paper's complete BVH on the device: the same tree as bvh::Tree (lib/src/bvh/tree.cpp) for
// the same positions, built, refit and measured with kernels over the shared per-node
// functions of snag/bvh/tree.h.
//
// Memory per triangle n (device): boxes 24 B x (2n - 1); the leaf permutation 4 B; build
// scratch, kept between builds: centroids 24 B, three position lists twice (24 B), flags 1 B,
// scan 12 B, sort keys 16 B: about 150 B per triangle.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <vector>

#include "device_buffer.cuh"
#include "snag/bvh/tree.h"
#include "snag/geom/predicates.h"
#include "snag/geom/vec3.h"
#include "snag/mesh/mesh.h"

namespace snag::cuda {

class DeviceTree {
 public:
  /// Makes room for a tree over n triangles (allocates only when n grows); scratch that must
  /// start zero is cleared on `stream`.
  void resize(int32_t n, cudaStream_t stream);

  /// Builds the tree over `mesh` (device pointers) on `stream`, then refits it. Asynchronous.
  ///
  /// The CPU orders each segment along the longest axis of its centroids' bounds (ties by
  /// triangle id) and splits it at the count the complete shape dictates. Here the centroids
  /// are sorted once along each axis (three radix sorts of (coordinate, id) keys), giving three
  /// lists of the triangles in position order; at each level every segment takes its bounds
  /// from the ends of the three lists (each list is sorted along its own axis within every
  /// segment), marks the first (split - begin) triangles of its chosen axis's list as left, and
  /// all three lists are stably partitioned by that mark (one scan over the 3n marks). A stable
  /// partition keeps each list sorted within the two halves, so the invariant holds for the
  /// next level, and each half gets exactly the set nth_element gives the CPU: the tree depends
  /// only on those sets, so it is the CPU's tree. O(n) work per level, four launches.
  void build(mesh::MeshView mesh, geom::PlaneCoefficients* planes, cudaStream_t stream);

  /// Recomputes every box from `mesh`'s positions, and planes[t] = detect::triangle_plane of
  /// every triangle t (the narrow phase's, computed where the corners are loaded anyway).
  /// Asynchronous.
  void refit(mesh::MeshView mesh, geom::PlaneCoefficients* planes, cudaStream_t stream);

  /// Sum of internal-node half areas over the root's (0 for a single leaf), in the blocked
  /// order of bvh::quality_block_sum, so that it is the CPU's bit for bit. Waits for the stream.
  double quality(cudaStream_t stream);
  /// Queues the quality (one launch) into pinned host memory; queued_quality() reads it once
  /// the stream has passed it.
  void queue_quality(cudaStream_t stream);
  double queued_quality() const { return *quality_host_.data(); }

  bool level_by_level_refit = false;

  bvh::TreeView view() const { return {shape_, boxes_.data(), triangle_at_.data()}; }
  const bvh::CompleteTree& shape() const { return shape_; }

 private:
  bvh::CompleteTree shape_;
  DeviceBuffer<geom::Box3f> boxes_;
  DeviceBuffer<int32_t> triangle_at_;
  DeviceBuffer<unsigned> refit_ticket_;  // subtrees fit; the last block resets it
  // Build scratch.
  DeviceBuffer<geom::Vec3d> centroids_;
  DeviceBuffer<int32_t> lists_, lists_alt_;  // three lists of n triangle ids, axis-major
  DeviceBuffer<uint8_t> left_;               // per triangle: goes to the left child this level
  DeviceBuffer<int32_t> scan_;               // 3n exclusive prefix sums of the left marks
  DeviceBuffer<uint64_t> keys_, keys_alt_;
  DeviceBuffer<int32_t> ids_;
  DeviceBuffer<unsigned char> temp_;
  DeviceBuffer<double> quality_blocks_;  // one sum per bvh::kQualityBlock internal nodes
  PinnedBuffer<double> quality_host_;
  double* quality_out_ = nullptr;          // quality_host_'s device address
  DeviceBuffer<unsigned> quality_ticket_;  // blocks done; the last one resets it
  int32_t capacity_ = 0;
};

}  // namespace snag::cuda
