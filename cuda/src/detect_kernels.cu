#include "detect_kernels.cuh"

#include <cooperative_groups.h>
#include <cooperative_groups/scan.h>

#include <algorithm>

#include "launch.cuh"
#include "snag/geom/narrow_phase.h"

namespace snag::cuda {

namespace {

namespace cg = cooperative_groups;

/// The calling thread's slot of *counter, which counts one per call: one atomic per group of
/// converged threads (warp-aggregated), not one per call.
__device__ __forceinline__ unsigned long long claim_slot(unsigned long long* counter) {
  const cg::coalesced_group group = cg::coalesced_threads();
  unsigned long long base = 0;
  if (group.thread_rank() == 0)
    base = atomicAdd(counter, static_cast<unsigned long long>(group.size()));
  return group.shfl(base, 0) + group.thread_rank();
}

/// Appends `value` at the next slot of `array`. Past `capacity` only the counter moves.
__device__ __forceinline__ void append(uint64_t* array, unsigned long long capacity,
                                       unsigned long long* counter, uint64_t value) {
  const unsigned long long at = claim_slot(counter);
  if (at < capacity) array[at] = value;
}

__device__ __forceinline__ uint64_t pack(int32_t high, int32_t low) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(high)) << 32) | static_cast<uint32_t>(low);
}

/// The Sink of detect::test_candidate_pair on the device: results go to global arrays, counts
/// stay in registers until the end of the thread's work.
struct DeviceSink {
  const ResultBuffers& out;
  unsigned long long misses = 0;
  unsigned long long expanded = 0;

  __device__ void hit(int32_t edge, int32_t triangle) {
    append(out.hits, out.hit_capacity, &out.counters->hits, pack(edge, triangle));
    expanded += static_cast<unsigned long long>(out.edge_face_offsets[edge + 1] -
                                                out.edge_face_offsets[edge]);
  }
  __device__ void uncertain(int32_t edge, int32_t triangle) {
    append(out.uncertain, out.uncertain_capacity, &out.counters->uncertain, pack(edge, triangle));
  }
  __device__ void miss() { ++misses; }
  __device__ void duplicate(int32_t a, int32_t b) {
    append(out.duplicates, out.duplicate_capacity, &out.counters->duplicates,
           pack(min(a, b), max(a, b)));
  }
};

/// Adds each thread's value into *total: a warp sum, then one atomic per warp. Every thread of
/// the block must call it.
__device__ __forceinline__ void add_warp_total(unsigned long long value,
                                               unsigned long long* total) {
  for (int offset = 16; offset > 0; offset >>= 1)
    value += __shfl_down_sync(0xffffffffu, value, offset);
  if ((threadIdx.x & 31) == 0 && value) atomicAdd(total, value);
}

/// A detect run's start: its counters zeroed and every slot of the pair set's table emptied,
/// in one launch where two memsets were two steps of the stream.
__global__ void clear_frame_kernel(FrameCounters* counters, unsigned long long* table,
                                   unsigned long long table_size) {
  wait_for_previous_kernel();
  const auto first = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const auto stride = static_cast<unsigned long long>(gridDim.x) * blockDim.x;
  if (first == 0) *counters = FrameCounters{};
  for (unsigned long long i = first; i < table_size; i += stride) table[i] = kEmptyKey;
}

/// One thread per triangle; with `publish`, the last block to finish (a ticket) copies the
/// counts there and leaves the counters zero for the next scan, so that a scan is one launch
/// per part, with no memset ahead of it and no copy after.
__global__ void scan_degenerate_kernel(const geom::Vec3d* positions, const geom::Tri* triangles,
                                       int32_t first, int32_t n, int32_t* degenerate,
                                       int32_t* uncertain, int32_t capacity, ScanCounters* counters,
                                       ScanCounts* publish) {
  wait_for_previous_kernel();
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < n) {
    const int32_t t = first + i;
    const geom::FilteredPredicates pred{positions};
    const geom::Tri tri = triangles[t];
    const geom::Answer answer = geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]);
    // Rare: a plain atomic per id. Within `capacity` whatever the counters held before (the
    // host checks the counts it reads).
    if (answer == geom::Answer::yes) {
      const unsigned long long at = atomicAdd(&counters->degenerate, 1ull);
      if (at < static_cast<unsigned long long>(capacity)) degenerate[at] = t;
    }
    if (answer == geom::Answer::uncertain) {
      const unsigned long long at = atomicAdd(&counters->uncertain, 1ull);
      if (at < static_cast<unsigned long long>(capacity)) uncertain[at] = t;
    }
  }
  if (!publish) return;
  __shared__ bool last;
  __threadfence();  // the block's counts are added before its ticket is
  __syncthreads();
  if (threadIdx.x == 0) last = atomicAdd(&counters->blocks_done, 1u) == gridDim.x - 1;
  __syncthreads();
  if (last && threadIdx.x == 0) {
    __threadfence();  // every other block's counts are read after its ticket
    publish->degenerate = atomicExch(&counters->degenerate, 0ull);
    publish->uncertain = atomicExch(&counters->uncertain, 0ull);
    counters->blocks_done = 0;
  }
}

__global__ void flag_degenerate_kernel(const int32_t* list, int32_t count, uint8_t* degenerate) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < count) degenerate[list[i]] = 1;
}

__global__ void planes_kernel(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n,
                              geom::PlaneCoefficients* planes) {
  wait_for_previous_kernel();
  const int32_t t = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (t < n) planes[t] = detect::triangle_plane(positions, triangles[t]);
}

/// position_of_triangle[triangle_at[p]] = p for every leaf position p of a tree over n
/// triangles (ids local to its part).
__global__ void leaf_positions_kernel(const int32_t* triangle_at, int32_t n,
                                      int32_t* position_of_triangle) {
  wait_for_previous_kernel();
  const int32_t p = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (p < n) position_of_triangle[triangle_at[p]] = p;
}

/// later[base + p], per leaf position p: bit d set when the leaf at p + 1 + d holds a triangle of
/// the fan of one of p's triangle's corners (its neighbours through a vertex with a fan, within the
/// 64 positions after p).
__global__ void later_neighbors_kernel(const int32_t* triangle_at, int32_t n, int32_t base,
                                       const geom::Tri* triangles, detect::FanView fans,
                                       const int32_t* position_of_triangle, uint64_t* later) {
  wait_for_previous_kernel();
  const int32_t p = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (p >= n) return;
  const geom::Tri tri = triangles[base + triangle_at[p]];
  uint64_t mask = 0;
  for (int k = 0; k < 3; ++k)
    for (int32_t s = fans.begin[tri.v[k]], end = fans.begin[tri.v[k] + 1]; s < end; ++s) {
      const int32_t face = fans.steps[s].face;
      if (face < 0) continue;
      const auto d = static_cast<uint32_t>(position_of_triangle[(face >> 1) - base] - p - 1);
      if (d < 64) mask |= uint64_t{1} << d;
    }
  later[base + p] = mask;
}

/// A walk's listing (of candidate pairs, or of subwalks): its thread's keys held in a small
/// local array and appended to the list a chunk at a time. Appending each key on its own
/// serialised the walks on the list's counter. A full chunk, met inside the walk's divergent
/// loop, is appended by its thread alone (one atomic per 16 keys: few walks list that many). The
/// rest is appended once the walk is over (finish), by every thread at that one call site together:
/// one atomic per group of converged threads. A group append inside the loop once counted pairs it
/// never wrote: with boxes padded to 32 bytes (tried, and slower), the recompiled walk listed
/// unwritten (zero) entries, caught by the tests and by memcheck in the pair tests. Not fully
/// explained; a thread appending alone cannot be mistaken about which threads take part.
class KeyLister {
 public:
  static constexpr int kChunk = 16;

  __device__ KeyLister(uint64_t* keys, unsigned long long capacity, unsigned long long* counter)
      : keys_(keys), capacity_(capacity), counter_(counter) {}

  __device__ __forceinline__ void add(uint64_t key) {
    held_[count_++] = key;
    if (count_ == kChunk) {
      store(atomicAdd(counter_, static_cast<unsigned long long>(kChunk)));
      count_ = 0;
    }
  }

  /// Appends what is held: the converged threads' counts summed across the group, one atomic.
  /// Called once, unconditionally, after the walk.
  __device__ void finish() {
    const cg::coalesced_group group = cg::coalesced_threads();
    const unsigned long long mine = static_cast<unsigned long long>(count_);
    const unsigned long long before = cg::exclusive_scan(group, mine);
    unsigned long long base = 0;
    if (group.thread_rank() == group.size() - 1 && before + mine > 0)
      base = atomicAdd(counter_, before + mine);
    store(group.shfl(base, group.size() - 1) + before);
    count_ = 0;
  }

 private:
  __device__ __forceinline__ void store(unsigned long long base) {
    for (int k = 0; k < count_; ++k)
      if (base + k < capacity_) keys_[base + k] = held_[k];
  }

  uint64_t* keys_;
  unsigned long long capacity_;
  unsigned long long* counter_;
  uint64_t held_[kChunk];
  int count_ = 0;
};

/// In a walk kernel whose first blocks hold `walkers` threads and whose blocks past them compute
/// the part's fans (FanJob), one vertex per thread: whether this block is one of the latter,
/// its fans then computed. The walks, a few warps per scheduler, leave the SMs room for them.
__device__ __forceinline__ bool fans_past_walks(const FanJob& fans, int32_t walkers) {
  const auto walk_blocks = static_cast<int32_t>((walkers + blockDim.x - 1) / blockDim.x);
  if (static_cast<int32_t>(blockIdx.x) < walk_blocks) return false;
  const int32_t v =
      (static_cast<int32_t>(blockIdx.x) - walk_blocks) * static_cast<int32_t>(blockDim.x) +
      static_cast<int32_t>(threadIdx.x);
  if (v < fans.count)
    fans.fan_clear[fans.first + v] =
        detect::fan_is_clear(fans.positions, fans.planes, fans.fans, fans.first + v);
  return true;
}

/// A part's walks above the split level: the leaf at `position` (so that a warp's triangles
/// are neighbours and follow nearly the same path) against the later leaves, handing over
/// (position, node) for every overlapping node at `first_unopened` or after (the split level
/// and under it; see SubwalkList). Nothing is loaded at a node handed over: degenerate
/// triangles and shared corners are the pair tests' business, so the walks are box tests only.
/// The blocks past the walks' compute the part's fans (FanJob), one vertex per thread: the
/// walks, at about two warps per scheduler, leave the SMs room for them.
__global__ void __launch_bounds__(kNarrowBlock)
    self_walk_kernel(bvh::TreeView tree, int32_t base, int32_t first_unopened,
                     const uint8_t* degenerate, FanJob fans, SubwalkList subwalks,
                     FrameCounters* counters) {
  wait_for_previous_kernel();
  if (fans_past_walks(fans, tree.shape.leaf_count)) return;
  const int32_t position = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (position >= tree.shape.leaf_count) return;
  const int32_t t = base + tree.triangle_at[position];
  if (degenerate[t]) return;
  KeyLister lister(subwalks.walks, subwalks.capacity, &counters->subwalks);
  bvh::for_each_later_overlapping_leaf(
      tree, position, [&](int32_t node) { lister.add(pack(position, node)); }, first_unopened);
  lister.finish();
}

/// A warp's listing: keys offered by its lanes together are staged in shared memory (kStage
/// per warp) and appended a batch at a time, one atomic per batch. Every call is made by the
/// whole warp at once.
class WarpLister {
 public:
  static constexpr unsigned kStage = 128;

  __device__ WarpLister(uint64_t* stage, uint64_t* keys, unsigned long long capacity,
                        unsigned long long* counter)
      : stage_(stage), keys_(keys), capacity_(capacity), counter_(counter) {}

  /// Each lane with `has` adds `key`.
  __device__ __forceinline__ void offer(bool has, uint64_t key) {
    const unsigned offering = __ballot_sync(0xffffffffu, has);
    if (!offering) return;
    if (count_ + 32 > kStage) flush();
    if (has) stage_[count_ + __popc(offering & ((1u << (threadIdx.x & 31)) - 1u))] = key;
    count_ += static_cast<unsigned>(__popc(offering));
  }

  /// Appends what is staged (and must be called once more after the last offer).
  __device__ void flush() {
    __syncwarp();
    if (count_ == 0) return;
    const unsigned lane = threadIdx.x & 31;
    unsigned long long base = 0;
    if (lane == 0) base = atomicAdd(counter_, static_cast<unsigned long long>(count_));
    base = __shfl_sync(0xffffffffu, base, 0);
    for (unsigned i = lane; i < count_; i += 32)
      if (base + i < capacity_) keys_[base + i] = stage_[i];
    __syncwarp();
    count_ = 0;
  }

 private:
  uint64_t* stage_;
  uint64_t* keys_;
  unsigned long long capacity_;
  unsigned long long* counter_;
  unsigned count_ = 0;  // the same in every lane
};

// Up to bvh::kSplitWarpNodes nodes at the split level (trees of up to 131,072 leaves), a self
// check's walks above that level run a warp per node (self_split_walk_kernel); above it, a
// thread per leaf (self_walk_kernel), whose chains are then spread over enough threads.
using bvh::kSplitWarpNodes;

/// The later nodes of the split level a warp collects before testing its leaves against them.
inline constexpr int kLaterChunk = 128;

/// A part's walks above the split level as self_walk_kernel hands them over, a warp per node a
/// of that level (in leaf order) instead of a thread per leaf: lane l holds the leaves l and
/// l + 32 under a (at most 64), and hands over for each (bvh::climb_under_split) the right
/// siblings of its climb up to a; then the warp tests every later node of the level
/// against a's box, 32 at a time, and each lane its leaves against those that overlap. Every
/// step is a few independent loads: the walks of one leaf each were chains of dependent ones
/// (57 box tests at most at 36K). The same (position, node) pairs, in another order; degenerate
/// leaves hand over nothing. The blocks past the walks' compute the part's fans (FanJob).
__global__ void __launch_bounds__(kNarrowBlock)
    self_split_walk_kernel(bvh::TreeView tree, int32_t base, const uint8_t* degenerate, FanJob fans,
                           SubwalkList subwalks, FrameCounters* counters) {
  wait_for_previous_kernel();
  const bvh::LevelNodes split = bvh::level_nodes(bvh::split_walk_level(tree.shape));
  if (fans_past_walks(fans, split.count * 32)) return;
  __shared__ uint64_t stage[kNarrowBlock / 32][WarpLister::kStage];
  __shared__ int32_t later[kNarrowBlock / 32][kLaterChunk];
  const int warp = static_cast<int>(threadIdx.x / 32), lane = static_cast<int>(threadIdx.x & 31);
  const int32_t end = split.first + split.count;
  const int32_t a =
      split.first + static_cast<int32_t>((blockIdx.x * blockDim.x + threadIdx.x) / 32);
  if (a >= end) return;  // a whole warp: blocks hold whole warps
  WarpLister lister(stage[warp], subwalks.walks, subwalks.capacity, &counters->subwalks);
  int32_t begin, past;
  tree.shape.positions_under(a, begin, past);
  int32_t position[2];
  bool walks[2];
  geom::Box3f box[2];
  for (int k = 0; k < 2; ++k) {
    position[k] = begin + lane + 32 * k;
    walks[k] = position[k] < past && !degenerate[base + tree.triangle_at[position[k]]];
    if (walks[k]) box[k] = tree.boxes[tree.shape.leaf_at(position[k])];
  }
  // The climb under the split level, each step a warp-wide offer.
  for (int k = 0; k < 2; ++k)
    bvh::climb_under_split(
        tree, walks[k] ? tree.shape.leaf_at(position[k]) : 0, box[k], split.first,
        [&](bool hand, int32_t sibling) { lister.offer(hand, pack(position[k], sibling)); });
  // The later nodes of the split level that overlap a, then the leaves against them, a chunk
  // at a time.
  const geom::Box3f a_box = tree.boxes[a];
  int count = 0;
  for (int32_t first = a + 1; first < end; first += 32) {
    const int32_t b = first + lane;
    const bool overlapping = b < end && geom::overlap(a_box, tree.boxes[b]);
    const unsigned found = __ballot_sync(0xffffffffu, overlapping);
    if (overlapping) later[warp][count + __popc(found & ((1u << lane) - 1u))] = b;
    count += __popc(found);
    if (count > kLaterChunk - 32 || first + 32 >= end) {
      __syncwarp();
      for (int i = 0; i < count; ++i) {
        const int32_t node = later[warp][i];
        const geom::Box3f node_box = tree.boxes[node];
        for (int k = 0; k < 2; ++k)
          lister.offer(walks[k] && geom::overlap(box[k], node_box), pack(position[k], node));
      }
      __syncwarp();
      count = 0;
    }
  }
  lister.flush();
}

/// Two parts' walks above the split level of `other`: the leaf at `position` of `tree` (part
/// a) against every leaf of `other`, as self_walk_kernel hands its nodes over.
__global__ void __launch_bounds__(kNarrowBlock)
    cross_walk_kernel(bvh::TreeView tree, int32_t base_a, bvh::TreeView other,
                      int32_t first_unopened, const uint8_t* degenerate, SubwalkList subwalks,
                      FrameCounters* counters) {
  wait_for_previous_kernel();
  const int32_t position = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (position >= tree.shape.leaf_count) return;
  if (degenerate[base_a + tree.triangle_at[position]]) return;
  KeyLister lister(subwalks.walks, subwalks.capacity, &counters->subwalks);
  const geom::Box3f box = tree.boxes[tree.shape.leaf_at(position)];
  bvh::for_each_overlapping_leaf(
      other, box, [&](int32_t node) { lister.add(pack(position, node)); }, first_unopened);
  lister.finish();
}

/// The rounds of 32 leaves a subwalk warp takes at once (subwalk_kernel). On an H200, one and
/// two each took the 36K frame from ~0.126 to ~0.117 ms in runs against the walked subwalks
/// (two leases, so not told apart); four, in two's run, was slower at 36K and on n-body
/// (0.123-0.132 and 0.259-0.274 ms against 0.116-0.117 and 0.243-0.245).
inline constexpr int kSubwalkRounds = 2;

/// The subwalks of one check: for each handed-over (position, node), the leaf at `position` of
/// `tree` (its triangle plus `base` is t) against the leaves under `node` of `walked` (the same
/// tree for a part against itself), listing (t, leaf) for every overlap. A warp takes 32
/// handovers, one a lane, and tests their leaves flat, 32 leaf boxes a round, each lane a leaf of
/// whichever handover it falls in: no walk, so no chain of dependent box tests. Walked one per
/// thread, the longest subwalks (37 to 51 box tests at 36K) held the kernel, at a few warps per
/// scheduler; flat, a 36K frame's ~100K handovers of 11 leaves on average take ~12 rounds a warp,
/// every load of a round independent of the others. Queued before the walks' count is known,
/// on a grid for the count expected (SubwalkList::expected), striding past that when there are
/// more.
__global__ void __launch_bounds__(kBlock)
    subwalk_kernel(bvh::TreeView tree, int32_t base, bvh::TreeView walked, NeighborDrop drop,
                   SubwalkList subwalks, CandidateList listed, FrameCounters* counters) {
  wait_for_previous_kernel();
  __shared__ uint64_t stage[kBlock / 32][WarpLister::kStage];
  constexpr unsigned kAll = 0xffffffffu;
  const auto first = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const auto stride = static_cast<unsigned long long>(gridDim.x) * blockDim.x;
  const unsigned long long count = counters->subwalks;
  if (first == 0) atomicMax(&counters->subwalks_most, count);
  const unsigned long long stored = min(count, subwalks.capacity);
  const int lane = static_cast<int>(threadIdx.x & 31);
  WarpLister lister(stage[threadIdx.x / 32], listed.pairs, listed.capacity, &counters->listed);
  unsigned long long dropped = 0;
  // The same for every lane of a warp (blocks hold whole warps), so the warp stays in step.
  for (unsigned long long warp_first = first - lane; warp_first < stored; warp_first += stride) {
    const unsigned long long i = warp_first + lane;
    int32_t t = 0, position = 0, begin = 0, past = 0;
    geom::Box3f box = geom::empty_box();
    uint64_t mask = 0;
    if (i < stored) {
      const uint64_t walk = subwalks.walks[i];
      position = static_cast<int32_t>(walk >> 32);
      t = base + tree.triangle_at[position];
      box = tree.boxes[tree.shape.leaf_at(position)];
      // The leaf's later neighbours left out: all of them when its three corners have clear
      // fans this frame, else none (NeighborDrop).
      if (drop.later) {
        const uint64_t later = drop.later[base + position];
        mask = detect::corners_clear(drop.fan_clear, drop.triangles[t]) ? later : 0;
      }
      walked.shape.positions_under(static_cast<int32_t>(walk & 0xffffffffu), begin, past);
    }
    // The warp's items: lane k's leaves are items [end_k - (past_k - begin_k), end_k), end_k
    // being the inclusive sum of the leaf counts up to lane k (so never decreasing).
    int32_t end = past - begin;
    for (int offset = 1; offset < 32; offset <<= 1) {
      const int32_t before = __shfl_up_sync(kAll, end, offset);
      if (lane >= offset) end += before;
    }
    const int32_t total = __shfl_sync(kAll, end, 31);
    // kSubwalkRounds rounds at once, so that their shuffles and loads overlap: a round alone is
    // a short chain (the owner's search, its box, the leaf's box, the test) that nothing hides.
    for (int32_t first_item = 0; first_item < total; first_item += 32 * kSubwalkRounds) {
      int32_t item[kSubwalkRounds], owner[kSubwalkRounds];
      for (int r = 0; r < kSubwalkRounds; ++r) {
        item[r] = first_item + 32 * r + lane;
        owner[r] = 0;
      }
      // Each item's handover: the first lane whose end is past it, found by halving.
      for (int step = 16; step > 0; step >>= 1)
        for (int r = 0; r < kSubwalkRounds; ++r)
          if (__shfl_sync(kAll, end, owner[r] + step - 1) <= item[r]) owner[r] += step;
      int32_t leaf[kSubwalkRounds], leaf_position[kSubwalkRounds];
      geom::Box3f leaf_box[kSubwalkRounds];
      for (int r = 0; r < kSubwalkRounds; ++r) {
        const int32_t owner_end = __shfl_sync(kAll, end, owner[r]);
        leaf_position[r] = __shfl_sync(kAll, past, owner[r]) - (owner_end - item[r]);
        // Past the last item, the root's box is read (it exists: total > 0) and ignored.
        leaf[r] = item[r] < total ? walked.shape.leaf_at(leaf_position[r]) : 0;
        leaf_box[r] = walked.boxes[leaf[r]];
      }
      for (int r = 0; r < kSubwalkRounds; ++r) {
        const int32_t owner_position = __shfl_sync(kAll, position, owner[r]);
        const int32_t owner_t = __shfl_sync(kAll, t, owner[r]);
        const uint64_t owner_mask = __shfl_sync(kAll, mask, owner[r]);
        geom::Box3f owner_box;
        for (int k = 0; k < 3; ++k) {
          owner_box.lo[k] = __shfl_sync(kAll, box.lo[k], owner[r]);
          owner_box.hi[k] = __shfl_sync(kAll, box.hi[k], owner[r]);
        }
        bool hit = false;
        if (item[r] < total && geom::overlap(owner_box, leaf_box[r])) {
          // Bit d of the mask: the leaf at position + 1 + d is a neighbour cleared by a fan.
          const auto d = static_cast<uint32_t>(leaf_position[r] - owner_position - 1);
          if (d < 64 && (owner_mask >> d & 1u))
            ++dropped;
          else
            hit = true;
        }
        lister.offer(hit, pack(owner_t, leaf[r]));
      }
    }
  }
  lister.flush();
  add_warp_total(dropped, &counters->candidates);
}

/// Calls visit(t, x) for each pair of the current check's list whose x (the leaf's triangle,
/// `walked_base` added) is not degenerate, the grid's threads striding over the pairs stored;
/// records the most listed and adds the pairs visited to counters->candidates. Every thread of
/// the block must call it (the count is a warp sum).
template <class Visit>
__device__ __forceinline__ void for_each_listed_pair(const PairInputs& in,
                                                     const bvh::TreeView& walked,
                                                     int32_t walked_base,
                                                     const CandidateList& listed,
                                                     FrameCounters* counters, Visit&& visit) {
  unsigned long long candidates = 0;
  const auto first = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const auto stride = static_cast<unsigned long long>(gridDim.x) * blockDim.x;
  const unsigned long long listed_count = counters->listed;
  if (first == 0) atomicMax(&counters->listed_most, listed_count);
  const unsigned long long stored = min(listed_count, listed.capacity);
  for (unsigned long long i = first; i < stored; i += stride) {
    const uint64_t pair = listed.pairs[i];
    const auto t = static_cast<int32_t>(pair >> 32);
    const auto leaf = static_cast<int32_t>(pair & 0xffffffffu);
    const int32_t x = walked_base + walked.triangle_at[walked.shape.position_of(leaf)];
    if (in.degenerate[x]) continue;
    ++candidates;
    visit(t, x);
  }
  add_warp_total(candidates, &counters->candidates);
}

/// The pair tests of one check with the filter left out (`--exact all`), one per listed (t,
/// leaf of `walked`) pair: every edge-triangle test the pair needs goes to the uncertain
/// buffer (detect::test_candidate_pair with defer_all computes no sides, so there is nothing
/// to screen). The kernel is queued before the walk's count is known: a fixed grid
/// (launch_counted) strides over the listed pairs.
__global__ void __launch_bounds__(kBlock)
    deferred_test_kernel(PairInputs in, bvh::TreeView walked, int32_t walked_base,
                         CandidateList listed, ResultBuffers out) {
  wait_for_previous_kernel();
  DeviceSink sink{out};
  for_each_listed_pair(in, walked, walked_base, listed, out.counters, [&](int32_t t, int32_t x) {
    detect::test_candidate_pair<detect::FilterUse::defer_all>(in.frame, in.topology, t, x, sink);
  });
  add_warp_total(sink.misses, &out.counters->misses);
  add_warp_total(sink.expanded, &out.counters->expanded);
}

/// The filtered path's pair tests in two launches. This one, light (few registers, so many
/// warps to hide its loads), screens every listed pair (shared corners from the ids, degenerate
/// triangles left out) up to the rejection by sides and keeps the pairs that get past it (a small
/// share: 4% of a cloth's neighbour pairs) for screened_test_kernel, which runs the whole test on
/// them. In one kernel, the edge tests' registers held every warp of the screen to a third of the
/// SM's slots, and each warp waited on its few threads that went on to edge tests.
__global__ void __launch_bounds__(kBlock)
    pair_screen_kernel(PairInputs in, bvh::TreeView walked, int32_t walked_base,
                       CandidateList listed, FrameCounters* counters) {
  wait_for_previous_kernel();
  for_each_listed_pair(in, walked, walked_base, listed, counters, [&](int32_t t, int32_t x) {
    uint32_t t_shared, x_shared;
    detect::shared_corners(in.topology.triangles[t], in.topology.triangles[x], t_shared, x_shared);
    if (detect::pair_passes_sides(in.frame, in.topology, t, x, t_shared, x_shared))
      listed.screened[claim_slot(&counters->screened)] = pack(t, x);
  });
}

/// The whole pair test of each pair the screen kept (at most one per listed pair stored, so
/// the list never overflows), on a grid for the count expected (CandidateList::
/// screened_expected), striding over the count.
__global__ void __launch_bounds__(kBlock)
    screened_test_kernel(PairInputs in, CandidateList listed, ResultBuffers out) {
  wait_for_previous_kernel();
  DeviceSink sink{out};
  const auto first = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const auto stride = static_cast<unsigned long long>(gridDim.x) * blockDim.x;
  const unsigned long long count = out.counters->screened;
  if (first == 0) atomicMax(&out.counters->screened_most, count);
  for (unsigned long long i = first; i < count; i += stride) {
    const uint64_t pair = listed.screened[i];
    detect::test_candidate_pair(in.frame, in.topology, static_cast<int32_t>(pair >> 32),
                                static_cast<int32_t>(pair & 0xffffffffu), sink);
  }
  add_warp_total(sink.misses, &out.counters->misses);
  add_warp_total(sink.expanded, &out.counters->expanded);
}

/// Adds pair `key` to the set; the thread that inserts it classifies it and appends it.
///
/// The table has at least twice as many slots as the set's pair capacity, but a run may bring
/// more distinct keys than that: the stored hits of non-manifold edges (three faces or more), the
/// duplicated faces, hits beyond what the last frame's pairs were sized for. A key that finds
/// the table full is dropped after one probe of every slot: every slot then holds a key whose
/// thread counted it in counters->pairs, so the count exceeds the pair capacity and the host
/// grows the buffers (the table to twice the expanded pairs and duplicates, which bound every
/// key) and runs the frame again. Probing on, it waited for a slot that never empties.
__device__ __forceinline__ void insert_pair(uint64_t key, int bits, const geom::Vec3d* positions,
                                            const geom::Tri* triangles, const PairSet& set,
                                            FrameCounters* counters) {
  const int32_t a = static_cast<int32_t>(key >> bits);
  const int32_t b = static_cast<int32_t>(key & ((1ull << bits) - 1));
  // Loaded ahead of the probe, whose atomics they would otherwise wait behind.
  const geom::Tri ta = triangles[a], tb = triangles[b];
  unsigned long long slot = (key * 0x9E3779B97F4A7C15ull) >> 20 & set.table_mask;
  for (unsigned long long probes = 0;; ++probes) {
    if (probes > set.table_mask) return;  // full: counted past the capacity (above)
    const unsigned long long was =
        atomicCAS(set.table + slot, kEmptyKey, static_cast<unsigned long long>(key));
    if (was == key) return;  // another thread has it
    if (was == kEmptyKey) break;
    slot = (slot + 1) & set.table_mask;
  }
  // Aggregated: one counter for every insertion of the frame, each its own atomic had
  // serialised them.
  const unsigned long long at = claim_slot(&counters->pairs);
  if (at >= set.pair_capacity) return;  // counted: the host grows the buffers and runs again
  const geom::FilteredPredicates pred{positions};
  const geom::Answer crossing = geom::is_crossing(pred, ta, tb);
  set.keys[at] = key;
  // bit 0: touching (PairKind's value), bit 1: certain
  set.status[at] = crossing == geom::Answer::uncertain
                       ? uint8_t{1}
                       : (crossing == geom::Answer::yes ? uint8_t{2} : uint8_t{3});
}

/// The hits' pairs and the duplicated faces into the pair set, hits first, two items per hit:
/// the first of its edge's faces, and the others (one, but for a non-manifold edge), so that a
/// thread's chain of loads, probe and classification is one pair's, not two in turn; then one
/// item per duplicated face pair. A fixed grid (launch_counted) strides over the stored items.
/// Past a capacity the narrow phase counted without storing: the host grows the buffers and
/// runs the frame again.
__global__ void expand_kernel(const uint64_t* hits, unsigned long long hit_capacity,
                              const uint64_t* duplicates, unsigned long long duplicate_capacity,
                              FrameCounters* counters, const int32_t* offsets, const int32_t* faces,
                              const uint8_t* degenerate, int bits, const geom::Vec3d* positions,
                              const geom::Tri* triangles, PairSet set) {
  wait_for_previous_kernel();
  const auto first = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  const auto stride = static_cast<unsigned long long>(gridDim.x) * blockDim.x;
  const unsigned long long hit_items = 2 * min(counters->hits, hit_capacity);
  const unsigned long long items = hit_items + min(counters->duplicates, duplicate_capacity);
  for (unsigned long long i = first; i < items; i += stride) {
    if (i < hit_items) {
      const uint64_t hit = hits[i >> 1];
      const int32_t edge = static_cast<int32_t>(hit >> 32);
      const int32_t triangle = static_cast<int32_t>(hit & 0xffffffffu);
      const int32_t begin = offsets[edge], end = offsets[edge + 1];
      const int32_t from = (i & 1) ? begin + 1 : begin, to = (i & 1) ? end : min(begin + 1, end);
      for (int32_t j = from; j < to; ++j) {
        const int32_t face = faces[j];
        if (face == triangle || degenerate[face]) continue;
        const uint64_t key = (static_cast<uint64_t>(min(face, triangle)) << bits) |
                             static_cast<uint64_t>(max(face, triangle));
        insert_pair(key, bits, positions, triangles, set, counters);
      }
    } else {
      const uint64_t d = duplicates[i - hit_items];
      insert_pair(((d >> 32) << bits) | (d & 0xffffffffu), bits, positions, triangles, set,
                  counters);
    }
  }
}

/// Ranks `count` distinct keys (at most kFinishLimit) and hands each, with its index and rank
/// (the count of smaller keys: its place in sorted order), to write(i, key, rank). Block (x,
/// y) of the grid compares the keys of slice x (kFinishThreads of them, one per thread)
/// against those of slice y, and adds what it counted into ranks[]; the last block done with
/// a slice (a ticket per slice) writes its keys out. A grid of fewer blocks strides over the
/// slices. Both arrays are zero before and after. Keys are distinct, so the ranks are a
/// permutation and the output is the sort's.
template <class Write>
__device__ void write_ranked(const uint64_t* keys, unsigned long long count, unsigned* ranks,
                             unsigned* tickets, Write&& write) {
  __shared__ uint64_t slice_keys[kFinishThreads];
  __shared__ bool last;
  const auto slices = static_cast<unsigned>((count + kFinishThreads - 1) / kFinishThreads);
  for (unsigned slice = blockIdx.x; slice < slices; slice += gridDim.x) {
    const unsigned long long i =
        static_cast<unsigned long long>(slice) * kFinishThreads + threadIdx.x;
    const uint64_t mine = i < count ? keys[i] : kEmptyKey;
    unsigned rank = 0;
    for (unsigned other = blockIdx.y; other < slices; other += gridDim.y) {
      const unsigned long long j =
          static_cast<unsigned long long>(other) * kFinishThreads + threadIdx.x;
      __syncthreads();                                            // the last slice's keys are read
      slice_keys[threadIdx.x] = j < count ? keys[j] : kEmptyKey;  // the empty key ranks last
      __syncthreads();
#pragma unroll 16
      for (int k = 0; k < kFinishThreads; ++k) rank += slice_keys[k] < mine;
    }
    if (i < count && rank) atomicAdd(&ranks[i], rank);
    __threadfence();  // the block's ranks are counted before its ticket is
    __syncthreads();
    if (threadIdx.x == 0) last = atomicAdd(&tickets[slice], 1u) == gridDim.y - 1;
    __syncthreads();
    if (last) {
      if (threadIdx.x == 0) tickets[slice] = 0;
      if (i < count) write(i, mine, atomicExch(&ranks[i], 0u));
    }
    __syncthreads();  // `last` is the next slice's
  }
}

/// The frame's results to host memory: when they fit (out.limit), the pairs (grid layer z =
/// 0) and the uncertain tests (z = 1) in sorted order, each ranked by its layer's blocks
/// together (write_ranked), the two side by side; the counters by block (0, 0, 0).
__global__ void __launch_bounds__(kFinishThreads)
    finish_kernel(const FrameCounters* counters, PairSet set, const uint64_t* uncertain,
                  unsigned long long uncertain_capacity, FinishScratch scratch, HostResults out) {
  wait_for_previous_kernel();
  const unsigned long long limit = min(out.limit, kFinishLimit);
  if (blockIdx.z == 0) {
    const unsigned long long pairs = counters->pairs;
    if (blockIdx.x == 0 && blockIdx.y == 0 && threadIdx.x == 0) *out.counters = *counters;
    if (pairs > 0 && pairs <= limit && pairs <= set.pair_capacity)
      write_ranked(set.keys, pairs, scratch.ranks, scratch.tickets,
                   [&](unsigned long long i, uint64_t key, unsigned rank) {
                     out.pairs[rank] = key | uint64_t{set.status[i]} << kStatusShift;
                   });
  } else {
    const unsigned long long tasks = counters->uncertain;
    if (tasks > 0 && tasks <= limit && tasks <= uncertain_capacity)
      write_ranked(
          uncertain, tasks, scratch.ranks + kFinishLimit, scratch.tickets + kFinishSlices,
          [&](unsigned long long, uint64_t key, unsigned rank) { out.uncertain[rank] = key; });
  }
}

}  // namespace

void launch_clear_frame(FrameCounters* counters, unsigned long long* table,
                        unsigned long long table_size, cudaStream_t stream) {
  // Four table slots per thread, at most 512 blocks: the table is 2^17 slots for most frames.
  const unsigned long long blocks =
      std::clamp<unsigned long long>((table_size + 4 * kBlock - 1) / (4 * kBlock), 1, 512);
  launch_chained(clear_frame_kernel, dim3(static_cast<unsigned>(blocks)), dim3(kBlock), stream,
                 counters, table, table_size);
}

void launch_scan_degenerate(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t first,
                            int32_t n, int32_t* degenerate, int32_t* uncertain, int32_t capacity,
                            ScanCounters* counters, ScanCounts* publish, cudaStream_t stream) {
  launch_chained_items(scan_degenerate_kernel, n, stream, positions, triangles, first, n,
                       degenerate, uncertain, capacity, counters, publish);
}

void launch_flag_degenerate(const int32_t* list, int32_t count, uint8_t* degenerate,
                            cudaStream_t stream) {
  launch(flag_degenerate_kernel, count, stream, list, count, degenerate);
}

void launch_planes(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n,
                   geom::PlaneCoefficients* planes, cudaStream_t stream) {
  launch_chained_items(planes_kernel, n, stream, positions, triangles, n, planes);
}

void launch_later_neighbors(const bvh::TreeView& tree, int32_t base, const geom::Tri* triangles,
                            detect::FanView fans, int32_t* position_of_triangle, uint64_t* later,
                            cudaStream_t stream) {
  const int32_t n = tree.shape.leaf_count;
  if (n <= 0) return;
  launch_chained_items(leaf_positions_kernel, n, stream, tree.triangle_at, n, position_of_triangle);
  launch_chained_items(later_neighbors_kernel, n, stream, tree.triangle_at, n, base, triangles,
                       fans, position_of_triangle, later);
}

namespace {

/// A launch whose item count is known only on the device, when it runs: a grid that covers
/// `bound` items (a buffer's capacity, or a count expected) but no more than `max_blocks`, the
/// kernel striding over the items the device counted. Capacities only grow: after one heavily
/// folded frame, a grid sized by them would launch mostly idle blocks for every later one.
template <class... Params, class... Args>
void launch_counted(void (*kernel)(Params...), unsigned long long bound, unsigned max_blocks,
                    cudaStream_t stream, Args&&... args) {
  const unsigned long long needed = (bound + kBlock - 1) / kBlock;
  const auto blocks = static_cast<unsigned>(
      std::max<unsigned long long>(1, std::min<unsigned long long>(needed, max_blocks)));
  launch_chained(kernel, dim3(blocks), dim3(kBlock), stream, std::forward<Args>(args)...);
}

void launch_pair_tests(const PairInputs& inputs, const bvh::TreeView& walked, int32_t walked_base,
                       const CandidateList& listed, const ResultBuffers& results,
                       detect::FilterUse use, unsigned max_blocks, cudaStream_t stream) {
  if (use == detect::FilterUse::certify) {
    // The screen's pairs cost about the same each: one wave of its blocks, striding, rather
    // than a second wave queued behind the first (62 registers: four blocks per SM, not the
    // eight of max_blocks). 36K triangles: 6 us less (cuda/NOTES.md, v9). The tests, whose
    // pairs vary widely, keep waves: a block that finishes early takes more.
    const unsigned screen_blocks = std::min(
        max_blocks, resident_blocks(reinterpret_cast<const void*>(&pair_screen_kernel), kBlock));
    launch_counted(pair_screen_kernel, listed.capacity, screen_blocks, stream, inputs, walked,
                   walked_base, listed, results.counters);
    launch_counted(screened_test_kernel, std::min(listed.screened_expected, listed.capacity),
                   max_blocks, stream, inputs, listed, results);
  } else
    launch_counted(deferred_test_kernel, listed.capacity, max_blocks, stream, inputs, walked,
                   walked_base, listed, results);
}

/// A grid for the subwalks expected, one per thread. Capped at max_blocks (as the pair tests
/// are), each thread ran its share of a large frame's subwalks one after another (ten each at
/// 1M triangles: traverse 1.0 -> 1.8 ms); one per thread, 1.09 ms. Sized by the expected count
/// rather than the capacity, which only grows: a heavy frame does not leave every later check
/// launching thousands of idle blocks.
void launch_subwalks(const bvh::TreeView& tree, int32_t base, const bvh::TreeView& walked,
                     const NeighborDrop& drop, const SubwalkList& subwalks,
                     const CandidateList& listed, const ResultBuffers& results,
                     cudaStream_t stream) {
  launch_counted(subwalk_kernel, std::min(subwalks.expected, subwalks.capacity), ~0u, stream, tree,
                 base, walked, drop, subwalks, listed, results.counters);
}

unsigned blocks_for(int32_t items, int block) {
  return static_cast<unsigned>((static_cast<int64_t>(items) + block - 1) / block);
}

}  // namespace

void launch_self_check(const bvh::TreeView& tree, int32_t base, const PairInputs& inputs,
                       const FanJob& fans, const NeighborDrop& drop, const SubwalkList& subwalks,
                       const CandidateList& listed, const ResultBuffers& results,
                       detect::FilterUse use, unsigned max_blocks, cudaStream_t stream) {
  if (tree.shape.leaf_count <= 0) return;
  // The walks' blocks, then the fans' (FanJob). Blocks of kNarrowBlock: 36K leaves are only
  // ~270 walks per SM of an H100, spread evenly; with a warp per node of the split level, two
  // nodes a block.
  const bvh::LevelNodes split = bvh::level_nodes(bvh::split_walk_level(tree.shape));
  const unsigned fan_blocks = blocks_for(std::max(fans.count, 0), kNarrowBlock);
  if (split.count <= kSplitWarpNodes) {
    launch_chained(self_split_walk_kernel,
                   dim3(blocks_for(split.count * 32, kNarrowBlock) + fan_blocks),
                   dim3(kNarrowBlock), stream, tree, base, inputs.degenerate, fans, subwalks,
                   results.counters);
  } else {
    launch_chained(self_walk_kernel,
                   dim3(blocks_for(tree.shape.leaf_count, kNarrowBlock) + fan_blocks),
                   dim3(kNarrowBlock), stream, tree, base, split.first, inputs.degenerate, fans,
                   subwalks, results.counters);
  }
  launch_subwalks(tree, base, tree, drop, subwalks, listed, results, stream);
  launch_pair_tests(inputs, tree, base, listed, results, use, max_blocks, stream);
}

void launch_cross_check(const bvh::TreeView& tree, int32_t base_a, const bvh::TreeView& other,
                        int32_t base_b, const PairInputs& inputs, const SubwalkList& subwalks,
                        const CandidateList& listed, const ResultBuffers& results,
                        detect::FilterUse use, unsigned max_blocks, cudaStream_t stream) {
  if (tree.shape.leaf_count <= 0 || other.shape.leaf_count <= 0) return;
  const int32_t first_unopened = bvh::CompleteTree::level_begin(bvh::split_walk_level(other.shape));
  launch_chained(cross_walk_kernel, dim3(blocks_for(tree.shape.leaf_count, kNarrowBlock)),
                 dim3(kNarrowBlock), stream, tree, base_a, other, first_unopened, inputs.degenerate,
                 subwalks, results.counters);
  launch_subwalks(tree, base_a, other, NeighborDrop{}, subwalks, listed, results, stream);
  launch_pair_tests(inputs, other, base_b, listed, results, use, max_blocks, stream);
}

void launch_expand(const uint64_t* hits, unsigned long long hit_capacity,
                   const uint64_t* duplicates, unsigned long long duplicate_capacity,
                   unsigned long long expected, FrameCounters* counters,
                   const int32_t* edge_face_offsets, const int32_t* edge_faces,
                   const uint8_t* degenerate, int bits, const geom::Vec3d* positions,
                   const geom::Tri* triangles, const PairSet& set, unsigned max_blocks,
                   cudaStream_t stream) {
  launch_counted(expand_kernel, std::min(expected, 2 * hit_capacity + duplicate_capacity),
                 max_blocks, stream, hits, hit_capacity, duplicates, duplicate_capacity, counters,
                 edge_face_offsets, edge_faces, degenerate, bits, positions, triangles, set);
}

void launch_finish(const FrameCounters* counters, const PairSet& set, const uint64_t* uncertain,
                   unsigned long long uncertain_capacity, unsigned long long expected,
                   const FinishScratch& scratch, const HostResults& out, cudaStream_t stream) {
  const auto slices = static_cast<unsigned>(std::clamp<unsigned long long>(
      (expected + kFinishThreads - 1) / kFinishThreads, 1, kFinishSlices));
  launch_chained(finish_kernel, dim3(slices, slices, 2), dim3(kFinishThreads), stream, counters,
                 set, uncertain, uncertain_capacity, scratch, out);
}

}  // namespace snag::cuda

SNAG_CUDA_TRACE_UNIT(detect_kernels)
