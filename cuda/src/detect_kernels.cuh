// The per-frame kernels of the CUDA backend, each a thin wrapper over the shared per-item
// functions (snag/geom/narrow_phase.h, snag/detect/pair_test.h), and their host launchers.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_check.cuh"
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
  unsigned long long pairs;  ///< distinct face pairs the expansion kept (entries wanted in `pairs`)
  unsigned long long listed;         ///< the current check's walks: candidate pairs they listed
  unsigned long long subwalks;       ///< the current check's walks above the split level: the
                                     ///< subwalks they handed over (zeroed with `listed` before
                                     ///< each check, the three side by side)
  unsigned long long screened;       ///< the current check's listed pairs past the screen
  unsigned long long listed_most;    ///< the most any check of the frame listed (entries wanted
                                     ///< in the candidate list)
  unsigned long long subwalks_most;  ///< likewise for the subwalk list
  unsigned long long screened_most;  ///< the most pairs any check's screen kept
};

/// The degenerate-triangle scan's counts on the device, zero between scans: the launch that
/// ends a scan publishes them (ScanCounts) and zeroes them again.
struct ScanCounters {
  unsigned long long degenerate;  ///< certainly degenerate triangles
  unsigned long long uncertain;   ///< the filter cannot tell
  unsigned blocks_done;           ///< the publishing launch's blocks done (its ticket)
};

/// A scan's counts as published, in host memory mapped into the device's address space
/// (written by the scan's last block, read by the host after the stream's sync).
struct ScanCounts {
  unsigned long long degenerate;
  unsigned long long uncertain;
};

/// Where a check's walk lists its candidate pairs for the pair tests: (t << 32 | leaf) keys, t
/// the walking leaf's triangle (a topology id), leaf a node of the tree walked. Past
/// `capacity` only counters->listed moves.
struct CandidateList {
  uint64_t* pairs = nullptr;
  unsigned long long capacity = 0;
  /// The (t << 32 | x) pairs that pass the screen (detect::pair_passes_sides), as many slots
  /// as `pairs`: at most every pair stored there passes.
  uint64_t* screened = nullptr;
  /// What the whole test's grid is sized for: the last frame's most screened pairs, with slack.
  /// A grid for the capacity, as the screen's, was mostly idle blocks: a settled cloth keeps
  /// about one listed pair in ten.
  unsigned long long screened_expected = 0;
};

/// Where a check's walks above the split level (bvh::split_walk_level) hand over the rest of
/// their work: (position << 32 | node) keys, position the walking leaf's (in its tree), node
/// an overlapping node of the tree walked, at the split level or under it, whose leaves are
/// still to be searched (a leaf itself, or a subtree of at most 64). Past `capacity` only
/// counters->subwalks moves.
struct SubwalkList {
  uint64_t* walks = nullptr;
  unsigned long long capacity = 0;
  unsigned long long expected = 0;  ///< what the subwalk kernel's grid is sized for
};

/// The pairs of a frame as the expansion leaves them: distinct (a << bits | b) keys, a < b, in
/// no particular order, each with its filtered kind (bit 0 = touching, bit 1 = certain), and
/// the open-addressing set that made them distinct (empty slots hold kEmptyKey; cleared before
/// every expansion). table_mask + 1 (a power of two) is at least twice pair_capacity; a run
/// that brings more keys than the table holds ends its probes after one pass over the table
/// and is run again with larger buffers (insert_pair).
struct PairSet {
  unsigned long long* table = nullptr;
  unsigned long long table_mask = 0;
  uint64_t* keys = nullptr;
  uint8_t* status = nullptr;
  unsigned long long pair_capacity = 0;
};

inline constexpr unsigned long long kEmptyKey = ~0ull;

/// Where finish_kernel puts a frame's results: host memory mapped into the device's address
/// space (written by the kernel, read by the host after the stream's sync), at most
/// `limit` pairs and `limit` uncertain tests; counters always. Each pair is one 8-byte store,
/// its key with its status in bits 62 and 63 (kStatusShift): the kernel's end waits for its
/// writes to cross the bus, and with the scattered stores of a key and of a status byte apart
/// it took 13.6 us at 3K pairs, 10.4 us now (cuda/NOTES.md, v9).
struct HostResults {
  uint64_t* pairs = nullptr;
  uint64_t* uncertain = nullptr;
  FrameCounters* counters = nullptr;
  unsigned long long limit = 0;
};

/// A pair's status (PairSet::status) above its key in HostResults::pairs: keys are below 2^62,
/// (a << bits | b) with bits at most 31.
inline constexpr int kStatusShift = 62;

/// finish_kernel ranks at most kFinishLimit pairs (and as many uncertain tests), comparing
/// every key with every other, kFinishThreads against kFinishThreads per block; frames with
/// more go through CUB's device-wide sort after the host has read the counts. At 3K pairs the
/// ranking takes 13 us over ~150 blocks, where one block's radix sort (CUB's BlockRadixSort,
/// 1024 threads) took 24 and no other shape of it took less than 18 (cuda/NOTES.md, v7).
inline constexpr int kFinishThreads = 256;
inline constexpr unsigned kFinishSlices = 32;
inline constexpr unsigned long long kFinishLimit = kFinishThreads * kFinishSlices;

/// finish_kernel's scratch, all zero between launches (each launch leaves it so): the ranks
/// being counted, kFinishLimit for the pairs then as many for the uncertain tests; the blocks
/// done with each slice of kFinishThreads keys, kFinishSlices for each.
struct FinishScratch {
  unsigned* ranks = nullptr;
  unsigned* tickets = nullptr;
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

/// What a self check's subwalks leave out: the leaves of a triangle's neighbours when its
/// three corners have clear fans (detect/fan.h). Such a pair shares a clear vertex, so its test
/// would end at once (detect::cleared_by_fan): left out of the list, it is counted as a
/// candidate and never screened. A triangle's later neighbours within 64 leaf positions are
/// known per tree build (`later`, launch_later_neighbors: 80% of a settled 36K cloth's); each
/// subwalk keeps them when its leaf's three corners are clear this frame (`fan_clear`, which
/// the walk kernel before it fills: FanJob). Null `later`: nothing is left out (no fans, the
/// filter deferred, or a frame with degenerate triangles, which are no candidates).
/// `later` is indexed by the topology's triangle range of the part: base + leaf position.
struct NeighborDrop {
  const uint64_t* later = nullptr;
  const geom::Tri* triangles = nullptr;
  const uint8_t* fan_clear = nullptr;
};

/// The fans of a part checked against itself this frame: fan_clear[v] =
/// detect::fan_is_clear(positions, planes, fans, v) for the vertices [first, first + count),
/// after the planes of their triangles. Computed by blocks of their own in the part's walk
/// kernel, beside the walks, which do not read them (the subwalks and the pair tests after it
/// do): a launch of its own took ~8 us of a 36K frame's chain. count 0: none (no fans, or the
/// filter deferred).
struct FanJob {
  const geom::Vec3d* positions = nullptr;
  const geom::PlaneCoefficients* planes = nullptr;
  detect::FanView fans;
  int32_t first = 0;
  int32_t count = 0;
  uint8_t* fan_clear = nullptr;
};

/// Everything the pair tests of one frame read.
struct PairInputs {
  detect::FrameView frame;
  detect::TopologyView topology;
  const uint8_t* degenerate = nullptr;  ///< per triangle, 1 when left out this frame
};

/// Zeroes *counters and fills the pair set's table (table_size slots) with kEmptyKey: the
/// start of every detect run. This launch and every other below but launch_flag_degenerate's is
/// chained (launch_chained).
void launch_clear_frame(FrameCounters* counters, unsigned long long* table,
                        unsigned long long table_size, cudaStream_t stream);

/// Degenerate-triangle scan of triangles [first, first + n): appends ids the filter finds
/// degenerate to `degenerate` and ids it cannot decide to `uncertain` (both in any order, after
/// those of earlier launches of the same scan; each array holds `capacity` ids, and a count past
/// it is left for the host to see), counting them in `counters`. A scan of several parts is a
/// launch per part; its last launch gives `publish`, where the counts go, and leaves `counters`
/// zero (the others give nullptr). No launch ahead of a scan clears anything.
void launch_scan_degenerate(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t first,
                            int32_t n, int32_t* degenerate, int32_t* uncertain, int32_t capacity,
                            ScanCounters* counters, ScanCounts* publish, cudaStream_t stream);

/// Sets degenerate[list[i]] = 1 (an ordinary launch: it follows a copy).
void launch_flag_degenerate(const int32_t* list, int32_t count, uint8_t* degenerate,
                            cudaStream_t stream);

/// For a tree just built over a part whose first triangle is `base`: later[base + p], per leaf
/// position p, has bit d set when the leaf at p + 1 + d holds a triangle of the fan of a corner
/// of p's triangle (NeighborDrop). position_of_triangle (the part's size) is scratch.
void launch_later_neighbors(const bvh::TreeView& tree, int32_t base, const geom::Tri* triangles,
                            detect::FanView fans, int32_t* position_of_triangle, uint64_t* later,
                            cudaStream_t stream);

/// planes[t] = the plane of triangle t (detect::triangle_plane). The refit computes them too; this
/// is for frames whose tree was not refit to the current positions.
void launch_planes(const geom::Vec3d* positions, const geom::Tri* triangles, int32_t n,
                   geom::PlaneCoefficients* planes, cudaStream_t stream);

/// A part against itself, in four launches. The walks, split at bvh::split_walk_level: one
/// thread per leaf position of its tree (in leaf order; the tree's triangle ids plus `base`
/// are the topology's) walks the later leaves' subtrees down to that level, handing every
/// overlapping node there to `subwalks` (for trees of up to 2,048 nodes at that level, a warp
/// per node of the level hands over the same, its leaves' climbs and the later nodes of the
/// level that overlap them: bvh::climb_under_split); then the subwalks, a warp per 32 of them,
/// test the leaves under each handed-over node flat (at most 64, all their boxes loaded side
/// by side rather than walked) and list every overlapping leaf into `listed`, counted in
/// results.counters->listed (which the caller zeroes first, with ->subwalks and ->screened).
/// The longest walk of a folded region's leaf (267 box tests at 36K) was the walk kernel's
/// time, at two warps per scheduler: split, it is two chains of at most ~60, the second over
/// three times as many threads. The pair tests: a light screen over every listed pair (shared
/// corners from the ids, degenerate triangles left out, then detect::pair_passes_sides) keeps
/// the pairs that get past the rejection by sides in listed.screened, and the whole test
/// (detect::test_candidate_pair) runs on those alone. The listed pairs are the CPU's
/// neighbour pairs and traversal candidates together, each once: triangles that share a
/// vertex always have overlapping boxes. Listing first keeps the walk to box tests (a walk
/// that tested its pairs, or loaded anything at its leaves, held its warp's other walks back
/// each time), and spreads the tests of a folded region's leaves over the whole device. With
/// FilterUse::defer_all every test goes to the uncertain buffer (`--exact all`), in one pair
/// test kernel of its own: it computes no sides to screen with. The subwalks run a lane per
/// handover; the screen on one wave of its blocks (at most `max_blocks`) striding over the list,
/// and the whole test on a grid for the pairs expected (CandidateList::screened_expected, at
/// most `max_blocks` blocks) striding over the pairs kept. `fans`: the part's fans, computed
/// beside the walks (FanJob); `drop`: the fan-cleared neighbours the subwalks leave out
/// (NeighborDrop).
void launch_self_check(const bvh::TreeView& tree, int32_t base, const PairInputs& inputs,
                       const FanJob& fans, const NeighborDrop& drop, const SubwalkList& subwalks,
                       const CandidateList& listed, const ResultBuffers& results,
                       detect::FilterUse use, unsigned max_blocks, cudaStream_t stream);

/// Two parts, the same way: one thread per leaf of `tree` (part a, whose first triangle is
/// base_a) walking all of `other` (part b) down to its split level, the subwalks under the
/// overlapping nodes there, then the pair tests of the list (parts share no vertex: no shared
/// corners).
void launch_cross_check(const bvh::TreeView& tree, int32_t base_a, const bvh::TreeView& other,
                        int32_t base_b, const PairInputs& inputs, const SubwalkList& subwalks,
                        const CandidateList& listed, const ResultBuffers& results,
                        detect::FilterUse use, unsigned max_blocks, cudaStream_t stream);

/// Every (face of the edge, triangle) pair of each hit, leaving out degenerate faces and the
/// triangle itself, and every duplicated face pair, made distinct in `set` and classified with
/// the double filter (detect::is_crossing) once each. Reads the counts from `counters` (the
/// narrow phase's), so it can be queued before they are known: a grid for the `expected` count
/// (at most `max_blocks` blocks) strides over the stored entries; entries past a count or past
/// a capacity are not read.
void launch_expand(const uint64_t* hits, unsigned long long hit_capacity,
                   const uint64_t* duplicates, unsigned long long duplicate_capacity,
                   unsigned long long expected, FrameCounters* counters,
                   const int32_t* edge_face_offsets, const int32_t* edge_faces,
                   const uint8_t* degenerate, int bits, const geom::Vec3d* positions,
                   const geom::Tri* triangles, const PairSet& set, unsigned max_blocks,
                   cudaStream_t stream);

/// When the frame's pairs and uncertain tests each fit (out.limit, at most kFinishLimit),
/// writes them to `out` in sorted order (pairs by key, uncertain tests by (edge, triangle));
/// always copies the counters to out.counters. The grid is sized for `expected` keys (the
/// larger count of the last frame); any count up to the limit is written.
void launch_finish(const FrameCounters* counters, const PairSet& set, const uint64_t* uncertain,
                   unsigned long long uncertain_capacity, unsigned long long expected,
                   const FinishScratch& scratch, const HostResults& out, cudaStream_t stream);

}  // namespace snag::cuda
