#include "device_tree.cuh"

#include <thrust/iterator/transform_iterator.h>

#include <algorithm>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cuda/atomic>

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

/// A leaf's triangle and its corners, loaded: every load of a leaf's fit, issued before any
/// of its stores, so that a thread fitting two leaves waits for both at once (a store to
/// `planes` between them would order the second leaf's loads after it).
struct LeafCorners {
  int32_t triangle;
  geom::Vec3d corner[3];
};

__device__ __forceinline__ LeafCorners load_leaf(const bvh::TreeView& tree,
                                                 const mesh::MeshView& mesh, int32_t p) {
  LeafCorners leaf;
  leaf.triangle = tree.triangle_at[p];
  const geom::Tri tri = mesh.triangles[leaf.triangle];
  for (int k = 0; k < 3; ++k) leaf.corner[k] = mesh.positions[tri.v[k]];
  return leaf;
}

/// The leaf's box and, into planes[], its triangle's plane, which the narrow phase reads
/// (computed here, where the corners are loaded anyway, instead of in a launch of its own):
/// bvh::leaf_box and detect::triangle_plane of the same corners.
__device__ __forceinline__ geom::Box3f fit_leaf(const LeafCorners& leaf,
                                                geom::PlaneCoefficients* planes) {
  planes[leaf.triangle] =
      geom::PlaneCoefficients::of(leaf.corner[0], leaf.corner[1], leaf.corner[2]);
  return bvh::leaf_box(leaf.corner[0], leaf.corner[1], leaf.corner[2]);
}

__device__ __forceinline__ geom::Box3f fit_leaf_and_plane(const bvh::TreeView& tree,
                                                          const mesh::MeshView& mesh,
                                                          geom::PlaneCoefficients* planes,
                                                          int32_t p) {
  return fit_leaf(load_leaf(tree, mesh, p), planes);
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

/// The refit in one launch. Each thread fits one node of level D - 1 (D the deepest level): a
/// leaf from its triangle, or an internal node from its two children, leaves of level D that
/// the thread fits first (the internal nodes of a level come before its leaves, so a warp's
/// internal nodes are a prefix of its lanes). A block of kRefitThreads threads covers the
/// subtree of kRefitLevels levels above level D - 1 under one node of level
/// top = D - 1 - kRefitLevels (0 for small trees): each warp fits the five levels above its 32
/// nodes in registers (a parent from its children's lanes by shuffles), the warps' roots meet in
/// shared memory behind the block's one barrier, and the first warp fits the levels up to
/// `top`. The last block to finish (a ticket, as the quality's) fits the levels above `top`
/// from the blocks' roots. Each box is geom::merge of the same two children or the
/// bvh::leaf_box of its corners, so the CPU's bits.
/// It replaced, in turn, a climb (one thread per leaf going up while it was the second child to
/// arrive, an atomic and a fence per level: 16 dependent steps through L2 at 36K, 22.5 us) and
/// blocks of 512 threads per subtree with a block barrier per level and boxes stored a float at
/// a time by lanes 24 bytes apart. Without those barriers and scattered stores the kernel takes
/// the same 12 us at 36K under ncu: what is left is a block's chain of dependent loads, the
/// last block's tail and the launch (cuda/NOTES.md, v14).
constexpr int kRefitLevels = 7;
constexpr int kRefitThreads = 1 << kRefitLevels;  // nodes of level D - 1 under a block's root
constexpr int kRefitWarps = kRefitThreads / 32;
/// The last block's first warp takes the blocks' roots into registers, up to this many a lane;
/// wider levels are merged through L2 by the whole block first.
constexpr int kRootsPerLane = 8;

constexpr int kBoxWords = sizeof(geom::Box3f) / sizeof(float);
static_assert(kBoxWords == 6, "a box is six floats, stored as words");

/// A warp's boxes on their way out: each lane puts its box at its slot (stage_box), then the
/// warp copies the slots to consecutive nodes as consecutive words (flush_boxes). A box stored
/// a float at a time by lanes 24 bytes apart touched three times the sectors it filled.
struct RefitStage {
  float words[kRefitWarps][2 * 32 * kBoxWords];  // up to 64 boxes: the children of 32 nodes
  geom::Box3f roots[kRefitWarps];
};

__device__ __forceinline__ void stage_box(float* stage, int slot, const geom::Box3f& box) {
  for (int k = 0; k < 3; ++k) {
    stage[slot * kBoxWords + k] = box.lo[k];
    stage[slot * kBoxWords + 3 + k] = box.hi[k];
  }
}

/// Stores the boxes of slots 0 .. count - 1 to nodes first .. first + count - 1. Every lane of
/// the warp calls it, after staging its boxes.
__device__ __forceinline__ void flush_boxes(float* stage, geom::Box3f* boxes, int32_t first,
                                            int count) {
  __syncwarp();
  float* const out = reinterpret_cast<float*>(boxes + first);
  for (int w = static_cast<int>(threadIdx.x & 31); w < count * kBoxWords; w += 32)
    out[w] = stage[w];
  __syncwarp();  // every slot is read before the stage is written again
}

/// The box that lane `src` holds, for every lane of the warp.
__device__ __forceinline__ geom::Box3f shuffle_box(const geom::Box3f& box, int src) {
  geom::Box3f got;
  for (int k = 0; k < 3; ++k) {
    got.lo[k] = __shfl_sync(0xffffffffu, box.lo[k], src);
    got.hi[k] = __shfl_sync(0xffffffffu, box.hi[k], src);
  }
  return got;
}

/// Lanes 0 .. count - 1 hold the boxes of the consecutive nodes from `first`, every node of
/// one subtree's level (count a power of two, at most 32): fits and stores their ancestors up
/// to that subtree's root, whose box lane 0 returns; `first` ends as the root. Every lane of
/// the warp calls it.
__device__ geom::Box3f fit_up_in_warp(float* stage, geom::Box3f* boxes, geom::Box3f box, int count,
                                      int32_t& first) {
  const int lane = static_cast<int>(threadIdx.x & 31);
  for (; count > 1; count /= 2) {
    const geom::Box3f left = shuffle_box(box, (2 * lane) & 31);
    const geom::Box3f right = shuffle_box(box, (2 * lane + 1) & 31);
    box = geom::merge(left, right);
    first = (first - 1) / 2;
    if (lane < count / 2) stage_box(stage, lane, box);
    flush_boxes(stage, boxes, first, count / 2);
  }
  return box;
}

/// A box written by another SM in this launch: read from L2 (__ldcg), past a possibly stale
/// L1 line.
__device__ __forceinline__ geom::Box3f load_from_l2(const geom::Box3f* box) {
  geom::Box3f loaded;
  const float* src = reinterpret_cast<const float*>(box);
  float* dst = reinterpret_cast<float*>(&loaded);
  for (int k = 0; k < kBoxWords; ++k) dst[k] = __ldcg(src + k);
  return loaded;
}

/// The last block's part: the levels above `top` from the 2^top blocks' roots in tree.boxes.
/// Levels of more than 32 * kRootsPerLane nodes are merged by the whole block through L2, a
/// barrier after each (past 2^16 triangles); then the first warp loads up to kRootsPerLane
/// consecutive nodes a lane, halves them in registers to one, and fits the rest by shuffles.
__device__ void fit_above_blocks(const bvh::TreeView& tree, float* stage, int32_t top) {
  int32_t level = top;
  for (; (1 << level) > 32 * kRootsPerLane; --level) {
    const int32_t first = CompleteTree::level_begin(level - 1);
    for (int32_t j = static_cast<int32_t>(threadIdx.x); j < (1 << (level - 1));
         j += kRefitThreads) {
      const int32_t node = first + j;
      tree.boxes[node] = geom::merge(load_from_l2(tree.boxes + 2 * node + 1),
                                     load_from_l2(tree.boxes + 2 * node + 2));
    }
    __syncthreads();
  }
  if (threadIdx.x >= 32) return;
  const int lane = static_cast<int>(threadIdx.x);
  const int lanes = min(1 << level, 32);
  int run = (1 << level) / lanes;  // consecutive nodes a lane holds: 1 .. kRootsPerLane
  int32_t first = CompleteTree::level_begin(level) + lane * run;
  geom::Box3f held[kRootsPerLane] = {};
#pragma unroll
  for (int k = 0; k < kRootsPerLane; ++k)
    if (k < run && lane < lanes) held[k] = load_from_l2(tree.boxes + first + k);
  // A run's nodes are the children of the next half as many: merged and stored, down to one.
  static_assert(kRootsPerLane == 8, "three halvings take a lane's run to one node");
#pragma unroll
  for (int halving = 0; halving < 3; ++halving) {
    if (run == 1) break;
    run /= 2;
    first = (first - 1) / 2;
#pragma unroll
    for (int k = 0; k < kRootsPerLane / 2; ++k)
      if (k < run) {
        held[k] = geom::merge(held[2 * k], held[2 * k + 1]);
        tree.boxes[first + k] = held[k];
      }
  }
  first = __shfl_sync(0xffffffffu, first, 0);
  fit_up_in_warp(stage, tree.boxes, held[0], lanes, first);
}

__global__ void __launch_bounds__(kRefitThreads)
    refit_subtrees_kernel(bvh::TreeView tree, mesh::MeshView mesh, geom::PlaneCoefficients* planes,
                          int32_t top, unsigned* ticket) {
  __shared__ RefitStage stage;
  __shared__ bool last;
  wait_for_previous_kernel();
  const int32_t depth = tree.shape.depth;
  if (depth == 0) {  // one triangle: the root is its leaf
    if (threadIdx.x == 0) tree.boxes[0] = fit_leaf_and_plane(tree, mesh, planes, 0);
    return;
  }
  // The block's nodes of level D - 1: `width` of them, every one of that level when top is 0
  // (a small tree, whose spare warps only join the barrier).
  const int32_t width = 1 << (depth - 1 - top);
  const int warp = static_cast<int>(threadIdx.x / 32), lane = static_cast<int>(threadIdx.x & 31);
  const int lanes = min(width, 32), warps = max(width / 32, 1);
  float* const warp_stage = stage.words[warp];
  int32_t first =
      CompleteTree::level_begin(depth - 1) + static_cast<int32_t>(blockIdx.x) * width + warp * 32;
  if (warp < warps) {
    const int32_t node = first + lane;
    const bool mine = lane < lanes;
    const bool internal = mine && !tree.shape.is_leaf(node);
    geom::Box3f box{}, left{}, right{};
    if (internal) {
      const LeafCorners a = load_leaf(tree, mesh, tree.shape.position_of(2 * node + 1));
      const LeafCorners b = load_leaf(tree, mesh, tree.shape.position_of(2 * node + 2));
      left = fit_leaf(a, planes);
      right = fit_leaf(b, planes);
      box = geom::merge(left, right);
    } else if (mine) {
      box = fit_leaf_and_plane(tree, mesh, planes, tree.shape.position_of(node));
    }
    // The children of the warp's internal nodes: consecutive nodes of level D, two a lane.
    const int internal_lanes = __popc(__ballot_sync(0xffffffffu, internal));
    if (internal_lanes > 0) {
      if (internal) {
        stage_box(warp_stage, 2 * lane, left);
        stage_box(warp_stage, 2 * lane + 1, right);
      }
      flush_boxes(warp_stage, tree.boxes, 2 * first + 1, 2 * internal_lanes);
    }
    if (mine) stage_box(warp_stage, lane, box);
    flush_boxes(warp_stage, tree.boxes, first, lanes);
    box = fit_up_in_warp(warp_stage, tree.boxes, box, lanes, first);
    if (lane == 0) stage.roots[warp] = box;
  }
  if (warps > 1) {
    // The warps' roots: consecutive nodes of one level, fit up to the block's root.
    __syncthreads();
    if (warp == 0) {
      // fit_up_in_warp left warp 0's `first` at its root, the first of the warps' roots.
      const geom::Box3f root = lane < warps ? stage.roots[lane] : geom::Box3f{};
      fit_up_in_warp(warp_stage, tree.boxes, root, warps, first);
    }
  }
  if (top == 0) return;

  // The levels above: the last block, once every block's root is stored. The root's words
  // were stored by lanes of the first warp, ordered before its lane 0 by flush_boxes'
  // __syncwarp; lane 0's ticket releases them (cumulatively) and, in the last block, acquires
  // every other block's. An acquire-release atomic, not __threadfence (fence.sc) and a plain
  // atomic: the same order at a lighter fence.
  if (warp == 0 && lane == 0) {
    ::cuda::atomic_ref<unsigned, ::cuda::thread_scope_device> blocks_done(*ticket);
    last = blocks_done.fetch_add(1u, ::cuda::memory_order_acq_rel) == gridDim.x - 1;
  }
  __syncthreads();
  if (!last) return;
  if (threadIdx.x == 0) *ticket = 0;
  fit_above_blocks(tree, stage.words[0], top);
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
    const int32_t top = std::max(0, shape_.depth - 1 - kRefitLevels);
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

SNAG_CUDA_TRACE_UNIT(device_tree)
