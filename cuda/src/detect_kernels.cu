#include "detect_kernels.cuh"

#include <cooperative_groups.h>

#include "launch.cuh"
#include "snag/geom/narrow_phase.h"

namespace snag::cuda {

namespace {

namespace cg = cooperative_groups;

/// Appends `value` at the next slot of `array`: one atomic per group of converged threads
/// (warp-aggregated), not one per result. Past `capacity` only the counter moves.
__device__ __forceinline__ void append(uint64_t* array, unsigned long long capacity, unsigned long long* counter,
                                       uint64_t value) {
  const cg::coalesced_group group = cg::coalesced_threads();
  unsigned long long base = 0;
  if (group.thread_rank() == 0) base = atomicAdd(counter, static_cast<unsigned long long>(group.size()));
  base = group.shfl(base, 0);
  const unsigned long long at = base + group.thread_rank();
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
    expanded += static_cast<unsigned long long>(out.edge_face_offsets[edge + 1] - out.edge_face_offsets[edge]);
  }
  __device__ void uncertain(int32_t edge, int32_t triangle) {
    append(out.uncertain, out.uncertain_capacity, &out.counters->uncertain, pack(edge, triangle));
  }
  __device__ void miss() { ++misses; }
  __device__ void duplicate(int32_t a, int32_t b) {
    append(out.duplicates, out.duplicate_capacity, &out.counters->duplicates, pack(min(a, b), max(a, b)));
  }
};

/// Adds each thread's value into *total: a warp sum, then one atomic per warp. Every thread of
/// the block must call it.
__device__ __forceinline__ void add_warp_total(unsigned long long value, unsigned long long* total) {
  for (int offset = 16; offset > 0; offset >>= 1) value += __shfl_down_sync(0xffffffffu, value, offset);
  if ((threadIdx.x & 31) == 0 && value) atomicAdd(total, value);
}

__global__ void scan_degenerate_kernel(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n,
                                       int32_t* degenerate, int32_t* uncertain, FrameCounters* counters) {
  const int32_t t = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (t >= n) return;
  const geom::FilteredPredicates pred{positions};
  const geom::Tri tri = triangles[t];
  const geom::Answer answer = geom::is_degenerate(pred, tri.v[0], tri.v[1], tri.v[2]);
  // Rare: a plain atomic per id.
  if (answer == geom::Answer::yes) degenerate[atomicAdd(&counters->degenerate, 1ull)] = t;
  if (answer == geom::Answer::uncertain) uncertain[atomicAdd(&counters->degenerate_uncertain, 1ull)] = t;
}

__global__ void flag_degenerate_kernel(const int32_t* list, int32_t count, uint8_t* degenerate) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < count) degenerate[list[i]] = 1;
}

__global__ void planes_kernel(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n,
                              geom::PlaneCoefficients* planes) {
  const int32_t t = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (t < n) planes[t] = detect::triangle_plane(positions, triangles[t]);
}

/// The neighbour pass: one thread per listed pair (their boxes always overlap).
__global__ void neighbor_pairs_kernel(PairInputs in, const std::array<int32_t, 2>* pairs, int64_t count,
                                      ResultBuffers out) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  DeviceSink sink{out};
  unsigned long long candidates = 0;
  if (i < count) {
    const int32_t t = pairs[i][0], x = pairs[i][1];
    if (!in.degenerate[t] && !in.degenerate[x]) {
      ++candidates;
      detect::test_candidate_pair(in.frame, in.topology, t, x, sink);
    }
  }
  add_warp_total(candidates, &out.counters->candidates);
  add_warp_total(sink.misses, &out.counters->misses);
  add_warp_total(sink.expanded, &out.counters->expanded);
}

/// The traversal: one thread per leaf position, in leaf order, so that a warp's triangles are
/// neighbours and follow nearly the same path; pairs of the neighbour list are skipped.
__global__ void traverse_kernel(bvh::TreeView tree, PairInputs in, ResultBuffers out) {
  const int32_t position = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  DeviceSink sink{out};
  unsigned long long candidates = 0;
  if (position < tree.shape.leaf_count) {
    const int32_t t = tree.triangle_at[position];
    if (!in.degenerate[t]) {
      const geom::Tri tt = in.topology.triangles[t];
      bvh::for_each_later_overlap(tree, position, [&](int32_t x) {
        if (in.degenerate[x] || detect::is_listed_neighbor(tt, in.topology.triangles[x], in.topology.listed_vertex,
                                                              in.topology.every_vertex_listed))
          return;
        ++candidates;
        detect::test_candidate_pair(in.frame, in.topology, t, x, sink);
      });
    }
  }
  add_warp_total(candidates, &out.counters->candidates);
  add_warp_total(sink.misses, &out.counters->misses);
  add_warp_total(sink.expanded, &out.counters->expanded);
}

__global__ void expand_kernel(const uint64_t* hits, unsigned long long hit_count, const uint64_t* duplicates,
                              unsigned long long duplicate_count, const int32_t* offsets, const int32_t* faces,
                              const uint8_t* degenerate, int bits, uint64_t* keys, unsigned long long* fill) {
  const unsigned long long i = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < hit_count) {
    const int32_t edge = static_cast<int32_t>(hits[i] >> 32);
    const int32_t triangle = static_cast<int32_t>(hits[i] & 0xffffffffu);
    for (int32_t j = offsets[edge]; j < offsets[edge + 1]; ++j) {
      const int32_t face = faces[j];
      if (face == triangle || degenerate[face]) continue;
      const uint64_t key = (static_cast<uint64_t>(min(face, triangle)) << bits) | static_cast<uint64_t>(max(face, triangle));
      keys[atomicAdd(fill, 1ull)] = key;
    }
  } else if (i < hit_count + duplicate_count) {
    const uint64_t d = duplicates[i - hit_count];
    keys[atomicAdd(fill, 1ull)] = ((d >> 32) << bits) | (d & 0xffffffffu);
  }
}

__global__ void classify_kernel(const uint64_t* keys, const unsigned long long* count, unsigned long long capacity,
                                int bits, uint64_t sentinel, const geom::Vec3d* positions, const geom::Tri* triangles,
                                uint8_t* status) {
  const unsigned long long i = static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= capacity || i >= *count || keys[i] == sentinel) return;
  const int32_t a = static_cast<int32_t>(keys[i] >> bits);
  const int32_t b = static_cast<int32_t>(keys[i] & ((1ull << bits) - 1));
  const geom::FilteredPredicates pred{positions};
  const geom::Answer crossing = geom::is_crossing(pred, triangles[a], triangles[b]);
  // bit 0: touching (PairKind's value), bit 1: certain
  status[i] = crossing == geom::Answer::uncertain ? uint8_t{1} : (crossing == geom::Answer::yes ? uint8_t{2} : uint8_t{3});
}

}  // namespace

void launch_scan_degenerate(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n, int32_t* degenerate,
                            int32_t* uncertain, FrameCounters* counters, cudaStream_t stream) {
  launch(scan_degenerate_kernel, n, stream, positions, triangles, n, degenerate, uncertain, counters);
}

void launch_flag_degenerate(const int32_t* list, int32_t count, uint8_t* degenerate, cudaStream_t stream) {
  launch(flag_degenerate_kernel, count, stream, list, count, degenerate);
}

void launch_planes(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n, geom::PlaneCoefficients* planes,
                   cudaStream_t stream) {
  launch(planes_kernel, n, stream, positions, triangles, n, planes);
}

void launch_narrow_phase(const bvh::TreeView& tree, const PairInputs& inputs,
                         const std::array<int32_t, 2>* neighbor_pairs, int64_t neighbor_pair_count,
                         const ResultBuffers& results, cudaStream_t stream) {
  launch(neighbor_pairs_kernel, neighbor_pair_count, stream, inputs, neighbor_pairs, neighbor_pair_count, results);
  launch(traverse_kernel, tree.shape.leaf_count, stream, tree, inputs, results);
}

void launch_expand(const uint64_t* hits, unsigned long long hit_count, const uint64_t* duplicates,
                   unsigned long long duplicate_count, const int32_t* edge_face_offsets, const int32_t* edge_faces,
                   const uint8_t* degenerate, int bits, uint64_t* keys, unsigned long long* fill, cudaStream_t stream) {
  launch(expand_kernel, static_cast<int64_t>(hit_count + duplicate_count), stream, hits, hit_count, duplicates,
         duplicate_count, edge_face_offsets, edge_faces, degenerate, bits, keys, fill);
}

void launch_classify(const uint64_t* keys, const unsigned long long* count, unsigned long long capacity, int bits,
                     uint64_t sentinel, const geom::Vec3d* positions, const geom::Tri* triangles, uint8_t* status,
                     cudaStream_t stream) {
  launch(classify_kernel, static_cast<int64_t>(capacity), stream, keys, count, capacity, bits, sentinel, positions,
         triangles, status);
}

}  // namespace snag::cuda
