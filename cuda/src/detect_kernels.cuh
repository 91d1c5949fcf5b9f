// The per-frame kernels of the CUDA backend, each a thin wrapper over the shared per-item
// functions (snag/geom/narrow_phase.h, snag/detect/pair_test.h), and their host launchers.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>

#include "snag/bvh/tree.h"
#include "snag/detect/pair_test.h"
#include "snag/detect/topology.h"
#include "snag/geom/predicates.h"

namespace snag::cuda {

/// Counters of one frame, on the device (zeroed before the pass that fills them). Appends go
/// past a buffer's capacity only in the counters: the host sees the overflow and traverses
/// again with larger buffers, so no result is ever lost.
struct FrameCounters {
  unsigned long long hits;        ///< edge-triangle hits (entries wanted in `hits`)
  unsigned long long uncertain;   ///< uncertain edge-triangle tests
  unsigned long long duplicates;  ///< duplicated faces
  unsigned long long candidates;  ///< candidate pairs tested
  unsigned long long misses;      ///< tests decided `no`
  unsigned long long expanded;    ///< sum over hits of the edge's face count: a bound on pairs
  unsigned long long degenerate;  ///< scan: certainly degenerate triangles
  unsigned long long degenerate_uncertain;  ///< scan: the filter cannot tell
};

/// Where the narrow phase appends its results. Hits and uncertain tests are (edge << 32 |
/// triangle) keys, duplicated faces (a << 32 | b) keys with a < b.
struct ResultBuffers {
  uint64_t* hits = nullptr;
  uint64_t* uncertain = nullptr;
  uint64_t* duplicates = nullptr;
  unsigned long long hit_capacity = 0, uncertain_capacity = 0, duplicate_capacity = 0;
  FrameCounters* counters = nullptr;
  const int32_t* edge_face_offsets = nullptr;
};

/// Everything the pair tests of one frame read.
struct PairInputs {
  detect::FrameView frame;
  detect::TopologyView topology;
  const uint8_t* degenerate = nullptr;  ///< per triangle, 1 when left out this frame
};

/// Degenerate-triangle scan: appends ids the filter finds degenerate to `degenerate` and ids it
/// cannot decide to `uncertain` (both in any order), counting them in counters.
void launch_scan_degenerate(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n, int32_t* degenerate,
                            int32_t* uncertain, FrameCounters* counters, cudaStream_t stream);

/// Sets degenerate[list[i]] = 1.
void launch_flag_degenerate(const int32_t* list, int32_t count, uint8_t* degenerate, cudaStream_t stream);

/// planes[t] = the plane of triangle t (detect::triangle_plane).
void launch_planes(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n, geom::PlaneCoefficients* planes,
                   cudaStream_t stream);

/// The candidate pairs of the neighbour list, then those of the traversal (one thread per leaf
/// position, in leaf order), each through detect::test_candidate_pair.
void launch_narrow_phase(const bvh::TreeView& tree, const PairInputs& inputs,
                         const std::array<int32_t, 2>* neighbor_pairs, int64_t neighbor_pair_count,
                         const ResultBuffers& results, cudaStream_t stream);

/// Every (face of the edge, triangle) pair of each hit, leaving out degenerate faces and the
/// triangle itself, and every duplicated face pair, as keys (a << bits | b) appended at
/// *fill to `keys`; the rest of `keys` keeps what it held (the caller's sentinel).
void launch_expand(const uint64_t* hits, unsigned long long hit_count, const uint64_t* duplicates,
                   unsigned long long duplicate_count, const int32_t* edge_face_offsets, const int32_t* edge_faces,
                   const uint8_t* degenerate, int bits, uint64_t* keys, unsigned long long* fill, cudaStream_t stream);

/// For each of the first *count keys (sorted unique pairs; the sentinel skipped), the kind with
/// the double filter: status[i] bit 0 = touching, bit 1 = certain.
void launch_classify(const uint64_t* keys, const unsigned long long* count, unsigned long long capacity, int bits,
                     uint64_t sentinel, const geom::Vec3d* positions, const geom::Tri* triangles, uint8_t* status,
                     cudaStream_t stream);

}  // namespace snag::cuda
