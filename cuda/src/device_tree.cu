#include "device_tree.cuh"

#include <thrust/iterator/transform_iterator.h>

#include <algorithm>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include "launch.cuh"
#include "snag/detect/pair_test.h"

namespace snag::cuda {

namespace {

using bvh::CompleteTree;

constexpr int kQualityThreads = 256;

/// A key whose unsigned order is the order of the double (finite, -0 == +0).
__device__ __forceinline__ uint64_t order_key(double x) {
  if (x == 0.0) x = 0.0;  // -0 and +0 compare equal on the CPU: give them one key
  const uint64_t bits = static_cast<uint64_t>(__double_as_longlong(x));
  return (bits & 0x8000000000000000ull) ? ~bits : (bits | 0x8000000000000000ull);
}

/// The centroid times three (the CPU's sum of corners, same order of additions) and, per axis,
/// the sort key of its coordinate with the triangle id beside it.
__global__ void centroid_keys_kernel(mesh::MeshView mesh, geom::Vec3d* centroids, uint64_t* keys,
                                     int32_t* ids) {
  const int32_t n = mesh.triangle_count;
  const int32_t t = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (t >= n) return;
  const geom::Tri tri = mesh.triangles[t];
  const geom::Vec3d c =
      mesh.positions[tri.v[0]] + mesh.positions[tri.v[1]] + mesh.positions[tri.v[2]];
  centroids[t] = c;
  for (int k = 0; k < 3; ++k) {
    keys[static_cast<size_t>(k) * n + t] = order_key(geom::coord(c, k));
    ids[static_cast<size_t>(k) * n + t] = t;
  }
}

/// The node of `level` whose leaf range holds position p. Position p is level-D slot p when
/// p < m, else a level-(D - 1) leaf standing for slots 2p - m and 2p - m + 1 (complete_tree.h).
__device__ __forceinline__ int32_t node_at_level(const CompleteTree& shape, int32_t p,
                                                 int32_t level) {
  const int32_t slot = p < shape.deepest_leaves ? p : 2 * p - shape.deepest_leaves;
  return CompleteTree::level_begin(level) + (slot >> (shape.depth - level));
}

/// The segment [begin, end) of position p at `level` and where it splits; a leaf (its segment
/// is one position) splits at its end, so that nothing moves.
__device__ __forceinline__ void segment_of(const CompleteTree& shape, int32_t p, int32_t level,
                                           int32_t& begin, int32_t& end, int32_t& split) {
  const int32_t node = node_at_level(shape, p, level);
  if (shape.is_leaf(node)) {
    begin = p;
    end = split = p + 1;
    return;
  }
  int32_t left_begin;
  shape.positions_under(node, begin, end);
  shape.positions_under(2 * node + 1, left_begin, split);
}

/// One thread per position p of the chosen axis's list: marks the triangle there left when p
/// is before the split. The bounds come from the ends of the three lists, as the CPU's min/max.
__global__ void mark_left_kernel(CompleteTree shape, int32_t level, const geom::Vec3d* centroids,
                                 const int32_t* lists, uint8_t* left) {
  const int32_t n = shape.leaf_count;
  const int32_t p = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (p >= n) return;
  int32_t begin, end, split;
  segment_of(shape, p, level, begin, end, split);
  if (end - begin == 1) {
    left[lists[p]] = 1;
    return;
  }
  double extent[3];
  for (int k = 0; k < 3; ++k) {
    const int32_t* list = lists + static_cast<size_t>(k) * n;
    extent[k] = geom::coord(centroids[list[end - 1]], k) - geom::coord(centroids[list[begin]], k);
  }
  const int axis =
      (extent[0] >= extent[1] && extent[0] >= extent[2]) ? 0 : (extent[1] >= extent[2] ? 1 : 2);
  left[lists[static_cast<size_t>(axis) * n + p]] = p < split ? 1 : 0;
}

struct LeftMark {
  const uint8_t* left;
  __host__ __device__ int32_t operator()(int32_t triangle) const { return left[triangle]; }
};

/// One thread per entry of the three lists: the stable partition of its segment by the marks.
__global__ void partition_kernel(CompleteTree shape, int32_t level, const int32_t* lists,
                                 const uint8_t* left, const int32_t* scan, int32_t* out) {
  const int32_t n = shape.leaf_count;
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= 3 * static_cast<int64_t>(n)) return;
  const int32_t k = static_cast<int32_t>(i / n),
                p = static_cast<int32_t>(i - static_cast<int64_t>(k) * n);
  const size_t base = static_cast<size_t>(k) * n;
  int32_t begin, end, split;
  segment_of(shape, p, level, begin, end, split);
  const int32_t t = lists[i];
  const int32_t left_before = scan[i] - scan[base + begin];  // left marks in [begin, p)
  const int32_t to = left[t] ? begin + left_before : split + (p - begin - left_before);
  out[base + to] = t;
}

/// The box of the leaf at position p, from its triangle, whose plane the narrow phase reads
/// (computed here, where the corners are loaded anyway, instead of in a launch of its own).
__device__ __forceinline__ geom::Box3f fit_leaf_and_plane(const bvh::TreeView& tree,
                                                          const mesh::MeshView& mesh,
                                                          geom::PlaneCoefficients* planes,
                                                          int32_t p) {
  const int32_t t = tree.triangle_at[p];
  const geom::Tri tri = mesh.triangles[t];
  planes[t] = detect::triangle_plane(mesh.positions, tri);
  return bvh::leaf_box(tri, mesh);
}

__global__ void refit_leaves_kernel(bvh::TreeView tree, mesh::MeshView mesh,
                                    geom::PlaneCoefficients* planes) {
  const int32_t n = tree.shape.leaf_count;
  const int32_t p = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (p < n) tree.boxes[tree.shape.leaf_at(p)] = fit_leaf_and_plane(tree, mesh, planes, p);
}

__global__ void refit_level_kernel(bvh::TreeView tree, int32_t first, int32_t last) {
  const int32_t node = first + static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (node < last) bvh::refit_internal(node, tree);
}

/// The refit in one launch, a CUDA block per subtree of kRefitLevels levels: the block of the
/// node at offset blockIdx.x of level top = depth - kRefitLevels (0 for small trees) fits its
/// subtree's nodes level by level from the deepest up, each level's boxes kept in shared memory
/// for the next, with a block barrier between levels. The last block to finish (a ticket, as
/// the quality's) fits the levels above `top` from the blocks' roots the same way. Each box is
/// geom::merge of the same two children or bvh::leaf_box, so the CPU's bits.
/// It replaced a climb (one thread per leaf going up while it was the second child to arrive,
/// an atomic and a fence per level: 16 dependent steps through L2 at 36K, 22.5 us) with about
/// kRefitLevels block barriers and one ticket.
constexpr int kRefitLevels = 9;
constexpr int kRefitWidth = 1 << kRefitLevels;  // nodes of a subtree's deepest level
constexpr int kRefitThreads = kRefitWidth;

/// Boxes of one level of a subtree being fit, and of the level above it: the level widths halve
/// going up, so two buffers of kRefitWidth and kRefitWidth / 2 boxes take turns.
struct RefitLevels {
  geom::Box3f wide[kRefitWidth];
  geom::Box3f narrow[kRefitWidth / 2];
};

/// The box of `node` from its children's boxes at `children` (the level below's, indexed from
/// that level's first node of this subtree) or, for a leaf, from its triangle.
__device__ __forceinline__ geom::Box3f fit_node(const bvh::TreeView& tree,
                                                const mesh::MeshView& mesh,
                                                geom::PlaneCoefficients* planes, int32_t node,
                                                const geom::Box3f* children, int32_t j) {
  if (!tree.shape.is_leaf(node)) return geom::merge(children[2 * j], children[2 * j + 1]);
  return fit_leaf_and_plane(tree, mesh, planes, tree.shape.position_of(node));
}

/// A box written by another SM in this launch: read from L2 (__ldcg), past a possibly stale
/// L1 line.
__device__ __forceinline__ geom::Box3f load_from_l2(const geom::Box3f* box) {
  geom::Box3f loaded;
  const float* src = reinterpret_cast<const float*>(box);
  float* dst = reinterpret_cast<float*>(&loaded);
  for (int k = 0; k < 6; ++k) dst[k] = __ldcg(src + k);
  return loaded;
}

/// Fits levels `deepest` up to `root_level` (inclusive) of the subtree under node `offset` of
/// `root_level`, one level at a time with a block barrier after each: every box goes to
/// tree.boxes and to `here`, which serves as the next level's `below` (the two swap). `below`
/// holds the boxes of the level under `deepest` when that level's nodes are internal. No level
/// of the subtree is wider than the buffer it goes to (RefitLevels).
__device__ void fit_subtree_levels(const bvh::TreeView& tree, const mesh::MeshView& mesh,
                                   geom::PlaneCoefficients* planes, int32_t root_level,
                                   int32_t offset, int32_t deepest, geom::Box3f* below,
                                   geom::Box3f* here) {
  const int32_t nodes = tree.shape.node_count();
  for (int32_t level = deepest; level >= root_level; --level) {
    const int32_t width = 1 << (level - root_level);
    const int32_t first = CompleteTree::level_begin(level) + offset * width;
    for (int32_t j = static_cast<int32_t>(threadIdx.x); j < width; j += kRefitThreads) {
      const int32_t node = first + j;
      if (node >= nodes) break;  // the deepest level ends early
      const geom::Box3f box = fit_node(tree, mesh, planes, node, below, j);
      tree.boxes[node] = box;
      here[j] = box;
    }
    __syncthreads();
    geom::Box3f* const filled = here;
    here = below;
    below = filled;
  }
}

__global__ void __launch_bounds__(kRefitThreads)
    refit_subtrees_kernel(bvh::TreeView tree, mesh::MeshView mesh, geom::PlaneCoefficients* planes,
                          int32_t top, unsigned* ticket) {
  __shared__ RefitLevels levels;
  __shared__ bool last;
  wait_for_previous_kernel();
  // The block's subtree: its deepest level (all leaves) needs no `below`.
  fit_subtree_levels(tree, mesh, planes, top, static_cast<int32_t>(blockIdx.x), tree.shape.depth,
                     levels.narrow, levels.wide);
  if (top == 0) return;

  // The levels above: the last block, once every block's root is stored.
  __threadfence();
  if (threadIdx.x == 0) last = atomicAdd(ticket, 1u) == gridDim.x - 1;
  __syncthreads();
  if (!last) return;
  if (threadIdx.x == 0) *ticket = 0;
  // Levels wider than the buffers (above 2^18 triangles) through L2, then the rest in shared
  // memory from the first level that fits.
  int32_t level = top;
  for (; (1 << level) > kRefitWidth; --level) {
    const int32_t first = CompleteTree::level_begin(level - 1);
    for (int32_t j = static_cast<int32_t>(threadIdx.x); j < (1 << (level - 1));
         j += kRefitThreads) {
      const int32_t node = first + j;
      tree.boxes[node] = geom::merge(load_from_l2(tree.boxes + 2 * node + 1),
                                     load_from_l2(tree.boxes + 2 * node + 2));
    }
    __syncthreads();
  }
  for (int32_t j = static_cast<int32_t>(threadIdx.x); j < (1 << level); j += kRefitThreads)
    levels.wide[j] = load_from_l2(tree.boxes + CompleteTree::level_begin(level) + j);
  __syncthreads();
  fit_subtree_levels(tree, mesh, planes, 0, 0, level - 1, levels.wide, levels.narrow);
}

/// The quality in one launch, one CUDA block per block of bvh::kQualityBlock internal nodes:
/// the block's threads compute the half areas side by side into shared memory, then the first
/// warp adds them in the CPU's order (bvh::quality_block_sum: a lane's partial sum per thread,
/// then lane 0 adding the partial sums in order; the same half_area and the same additions,
/// so the same bits), reading shared memory instead of waiting on a global load per node (that
/// wait made it 0.26 ms at 36K, 3 ms at 1M). The last block to finish adds the block sums in
/// order (bvh::quality_from_blocks) and resets the ticket.
__global__ void __launch_bounds__(kQualityThreads)
    quality_kernel(const geom::Box3f* boxes, bvh::CompleteTree shape, int32_t blocks,
                   double* block_sums, unsigned* ticket, double* out) {
  static_assert(bvh::kQualityLanes == 32, "a block's lanes are one warp's threads");
  __shared__ double areas[bvh::kQualityBlock];
  __shared__ bool last;
  wait_for_previous_kernel();
  const int32_t block = static_cast<int32_t>(blockIdx.x);
  const int32_t begin = block * bvh::kQualityBlock;
  const int32_t count = bvh::quality_block_size(shape, block);
  for (int32_t k = static_cast<int32_t>(threadIdx.x); k < count; k += kQualityThreads)
    areas[k] = geom::half_area(boxes[begin + k]);
  __syncthreads();
  if (threadIdx.x < bvh::kQualityLanes) {
    const int32_t lane = static_cast<int32_t>(threadIdx.x);
    const double partial = bvh::quality_lane_sum([&](int32_t k) { return areas[k]; }, count, lane);
    __syncwarp();
    areas[lane] = partial;  // every lane has read what it needed of areas[]
    __syncwarp();
    if (lane == 0) {
      double sum = 0.0;
      for (int32_t l = 0; l < bvh::kQualityLanes; ++l) sum += areas[l];
      block_sums[block] = sum;
      __threadfence();  // the sum is visible device-wide before the ticket counts it
      last = atomicAdd(ticket, 1u) == static_cast<unsigned>(blocks - 1);
    }
  }
  __syncthreads();
  if (!last || threadIdx.x != 0) return;
  // Every other block's sum was fenced before its ticket; this SM never read those lines, so
  // the loads below go to L2 and see them.
  __threadfence();
  *ticket = 0;
  *out = bvh::quality_from_blocks(block_sums, blocks, boxes[0]);
}

}  // namespace

void DeviceTree::resize(int32_t n, cudaStream_t stream) {
  shape_ = n > 0 ? CompleteTree(n) : CompleteTree();
  if (n <= capacity_) return;
  const size_t count = static_cast<size_t>(n);
  boxes_.reserve(2 * count - 1);
  triangle_at_.reserve(count);
  refit_ticket_.reserve(1);
  // On the caller's stream: a plain cudaMemset goes on the legacy stream, which does not
  // order with the backend's non-blocking streams.
  SNAG_CUDA_CHECK(cudaMemsetAsync(refit_ticket_.data(), 0, sizeof(unsigned), stream));
  centroids_.reserve(count);
  lists_.reserve(3 * count);
  lists_alt_.reserve(3 * count);
  left_.reserve(count);
  scan_.reserve(3 * count);
  keys_.reserve(3 * count);
  keys_alt_.reserve(3 * count);
  ids_.reserve(3 * count);
  quality_host_.reserve(1);
  quality_out_ = mapped(quality_host_.data());
  quality_ticket_.reserve(1);
  SNAG_CUDA_CHECK(cudaMemsetAsync(quality_ticket_.data(), 0, sizeof(unsigned), stream));
  quality_blocks_.reserve(static_cast<size_t>((n + bvh::kQualityBlock - 1) / bvh::kQualityBlock));
  // Scratch for the sorts and the scans, sized for the largest of them.
  size_t sort_bytes = 0, scan_bytes = 0;
  SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, keys_.data(),
                                                  keys_alt_.data(), ids_.data(), lists_.data(), n));
  auto marks = thrust::make_transform_iterator(lists_.data(), LeftMark{left_.data()});
  SNAG_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, marks, scan_.data(), 3 * n));
  temp_.reserve(std::max(sort_bytes, scan_bytes));
  capacity_ = n;
}

void DeviceTree::build(mesh::MeshView mesh, geom::PlaneCoefficients* planes, cudaStream_t stream) {
  const int32_t n = mesh.triangle_count;
  resize(n, stream);
  if (n == 0) return;
  const size_t count = static_cast<size_t>(n);
  launch(centroid_keys_kernel, n, stream, mesh, centroids_.data(), keys_.data(), ids_.data());
  for (int k = 0; k < 3; ++k) {
    // Stable: equal coordinates keep the ids' increasing order, the CPU's tie-break.
    size_t bytes = temp_.capacity();
    SNAG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(
        temp_.data(), bytes, keys_.data() + k * count, keys_alt_.data() + k * count,
        ids_.data() + k * count, lists_.data() + k * count, n, 0, 64, stream));
  }
  for (int32_t level = 0; level < shape_.depth; ++level) {
    launch(mark_left_kernel, n, stream, shape_, level, centroids_.data(), lists_.data(),
           left_.data());
    size_t bytes = temp_.capacity();
    auto marks = thrust::make_transform_iterator(lists_.data(), LeftMark{left_.data()});
    SNAG_CUDA_CHECK(
        cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, marks, scan_.data(), 3 * n, stream));
    launch(partition_kernel, 3 * n, stream, shape_, level, lists_.data(), left_.data(),
           scan_.data(), lists_alt_.data());
    lists_.swap(lists_alt_);
  }
  // Every list holds the leaf order now; the first one becomes the permutation.
  SNAG_CUDA_CHECK(cudaMemcpyAsync(triangle_at_.data(), lists_.data(), count * sizeof(int32_t),
                                  cudaMemcpyDeviceToDevice, stream));
  refit(mesh, planes, stream);
}

void DeviceTree::refit(mesh::MeshView mesh, geom::PlaneCoefficients* planes, cudaStream_t stream) {
  const int32_t n = shape_.leaf_count;
  if (n == 0) return;
  const bvh::TreeView tree = view();
  if (!level_by_level_refit) {
    const int32_t top = std::max(0, shape_.depth - kRefitLevels);
    launch_chained(refit_subtrees_kernel, dim3(1u << top), dim3(kRefitThreads), stream, tree, mesh,
                   planes, top, refit_ticket_.data());
    return;
  }
  launch(refit_leaves_kernel, n, stream, tree, mesh, planes);
  for (int32_t level = shape_.depth - 1; level >= 0; --level) {
    const int32_t first = CompleteTree::level_begin(level);
    const int32_t last = std::min(CompleteTree::level_begin(level + 1), n - 1);
    if (last > first) launch(refit_level_kernel, last - first, stream, tree, first, last);
  }
}

void DeviceTree::queue_quality(cudaStream_t stream) {
  const int32_t blocks = bvh::quality_block_count(shape_);
  if (blocks == 0) {
    *quality_host_.data() = 0.0;
    return;
  }
  launch_chained(quality_kernel, dim3(static_cast<unsigned>(blocks)), dim3(kQualityThreads), stream,
                 boxes_.data(), shape_, blocks, quality_blocks_.data(), quality_ticket_.data(),
                 quality_out_);
}

double DeviceTree::quality(cudaStream_t stream) {
  queue_quality(stream);
  SNAG_CUDA_CHECK(cudaStreamSynchronize(stream));
  return queued_quality();
}

}  // namespace snag::cuda
