#include "snag/detect/pairs.h"

#include <algorithm>

#include <omp.h>

#include "snag/detect/pair_test.h"
#include "snag/geom/narrow_phase.h"

namespace snag::detect {

namespace {

/// Sorts and deduplicates keys below 2^bits with a least-significant-digit radix sort: linear
/// in the count, where a comparison sort of a frame's hundreds of thousands of hit pairs was a
/// third of the frame. The fewest passes of digits of at most 12 bits (4,096 counts, 32 KB: in
/// L1 with room to spare), the bits spread evenly over them: cloth-ball's 34-bit keys take three
/// passes of 12 bits where 11-bit digits took four (expand_hits on its frames 3.1-3.2 -> 2.5-2.8
/// ms on the 2-core EPYC), 36K's 32-bit keys three of 11 as before.
///
/// Each pass is shared among `threads`: each counts the digits of its own run of keys, and
/// puts them after the same digit's keys of the runs before its own, so that every pass is
/// stable and the result is the same for every thread count.
void sort_unique(std::vector<uint64_t>& keys, int bits, int threads) {
  constexpr int kMaxDigit = 12;
  const int passes = (bits + kMaxDigit - 1) / kMaxDigit;
  const int digit = (bits + passes - 1) / passes;
  const size_t buckets = size_t{1} << digit;
  const auto count = static_cast<int64_t>(keys.size());
  // Below this many keys per thread, one thread does it all (a pass's counts outweigh them).
  constexpr int64_t kKeysPerThread = 16384;
  const int team = static_cast<int>(std::clamp<int64_t>(count / kKeysPerThread, 1, threads));
  std::vector<uint64_t> scratch(keys.size());
  if (team == 1) {  // without a parallel region: at a small frame's few keys, it cost ~15 us
    std::vector<size_t> start(buckets + 1);
    for (int shift = 0; shift < bits; shift += digit) {
      std::fill(start.begin(), start.end(), 0);
      for (uint64_t k : keys) ++start[((k >> shift) & (buckets - 1)) + 1];
      for (size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
      for (uint64_t k : keys) scratch[start[(k >> shift) & (buckets - 1)]++] = k;
      keys.swap(scratch);
    }
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    return;
  }
  // start[t * buckets + b]: where run t's first key of digit b goes.
  std::vector<int64_t> start(static_cast<size_t>(team) * buckets);
  // The runtime may give fewer threads than asked for (OMP_THREAD_LIMIT, nesting): the runs
  // are those of the team it gives.
#pragma omp parallel num_threads(team)
  {
    const int t = omp_get_thread_num(), runs = omp_get_num_threads();
    const int64_t first = count * t / runs, last = count * (t + 1) / runs;
    int64_t* mine = start.data() + static_cast<size_t>(t) * buckets;
    for (int shift = 0; shift < bits; shift += digit) {
      std::fill(mine, mine + buckets, 0);
      for (int64_t i = first; i < last; ++i) ++mine[(keys[i] >> shift) & (buckets - 1)];
#pragma omp barrier
#pragma omp single
      {
        int64_t at = 0;
        for (size_t b = 0; b < buckets; ++b)
          for (int r = 0; r < runs; ++r) {
            int64_t& slot = start[static_cast<size_t>(r) * buckets + b];
            const int64_t run_count = slot;
            slot = at;
            at += run_count;
          }
      }  // the single's closing barrier: every run's starts are set
      for (int64_t i = first; i < last; ++i)
        scratch[mine[(keys[i] >> shift) & (buckets - 1)]++] = keys[i];
#pragma omp barrier
#pragma omp single
      keys.swap(scratch);
    }
  }
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

int bits_for(int64_t count) {
  int bits = 1;
  while ((int64_t{1} << bits) < count) ++bits;
  return bits;
}

/// The pairs of sorted unique keys a << id_bits | b, of kind `touching`.
std::vector<FacePair> pairs_of(const std::vector<uint64_t>& keys, int id_bits) {
  std::vector<FacePair> pairs(keys.size());
  const uint64_t low = (uint64_t{1} << id_bits) - 1;
  for (size_t i = 0; i < keys.size(); ++i)
    pairs[i] = {static_cast<int32_t>(keys[i] >> id_bits), static_cast<int32_t>(keys[i] & low),
                PairKind::touching};
  return pairs;
}

}  // namespace

std::vector<FacePair> expand_hits(const Topology& topo, std::span<const EdgeTriangleTask> hits,
                                  std::span<const uint8_t> degenerate_flags, int threads) {
  // Pairs packed as a << id_bits | b, so that sorting the keys sorts by (a, b).
  const int id_bits = bits_for(topo.triangle_count());
  const auto hit_count = static_cast<int64_t>(hits.size());
  constexpr int64_t kHitsPerThread = 8192;
  const int team = static_cast<int>(std::clamp<int64_t>(hit_count / kHitsPerThread, 1, threads));
  // The keys of hits [first, last), appended to `out`.
  auto list_keys = [&](int64_t first, int64_t last, std::vector<uint64_t>& out) {
    out.reserve(out.size() + static_cast<size_t>(last - first) * 2);
    for (int64_t h = first; h < last; ++h) {
      // A hit's edge is anywhere in the edge lists: its faces waited on two cache misses, one
      // after the other. Ahead of time, the offsets of the hit 16 on, then the faces of the hit
      // 8 on (its offsets by then in cache).
      if (h + 16 < last) __builtin_prefetch(&topo.edge_face_offsets[hits[h + 16].edge]);
      if (h + 8 < last)
        __builtin_prefetch(&topo.edge_faces[topo.edge_face_offsets[hits[h + 8].edge]]);
      const EdgeTriangleTask& hit = hits[h];
      for (int32_t i = topo.edge_face_offsets[hit.edge]; i < topo.edge_face_offsets[hit.edge + 1];
           ++i) {
        const int32_t face = topo.edge_faces[i];
        if (face == hit.triangle || degenerate_flags[face]) continue;
        const auto a = static_cast<uint64_t>(std::min(face, hit.triangle));
        const auto b = static_cast<uint64_t>(std::max(face, hit.triangle));
        out.push_back(a << id_bits | b);
      }
    }
  };
  std::vector<uint64_t> keys;
  if (team == 1) {
    list_keys(0, hit_count, keys);
    sort_unique(keys, 2 * id_bits, threads);
    return pairs_of(keys, id_bits);
  }
  // Each thread lists the keys of its own run of hits; the lists are then joined in run order.
  // (Runs of the team the runtime gives, as in sort_unique.)
  std::vector<std::vector<uint64_t>> run_keys(static_cast<size_t>(team));
#pragma omp parallel num_threads(team)
  {
    const int t = omp_get_thread_num(), runs = omp_get_num_threads();
    std::vector<uint64_t>& out = run_keys[static_cast<size_t>(t)];
    list_keys(hit_count * t / runs, hit_count * (t + 1) / runs, out);
#pragma omp barrier
#pragma omp single
    {
      size_t total = 0;
      for (int r = 0; r < runs; ++r) total += run_keys[static_cast<size_t>(r)].size();
      keys.resize(total);
    }
    size_t at = 0;
    for (int r = 0; r < t; ++r) at += run_keys[static_cast<size_t>(r)].size();
    std::copy(out.begin(), out.end(), keys.begin() + static_cast<std::ptrdiff_t>(at));
  }
  sort_unique(keys, 2 * id_bits, threads);
  return pairs_of(keys, id_bits);
}

void merge_pairs(std::vector<FacePair>& into, std::vector<uint8_t>& into_flags,
                 std::span<const FacePair> more, std::span<const uint8_t> more_flags) {
  if (more.empty()) return;  // most frames: nothing to merge, no copy of a long list
  std::vector<FacePair> merged;
  std::vector<uint8_t> flags;
  merged.reserve(into.size() + more.size());
  flags.reserve(into.size() + more.size());
  size_t i = 0, j = 0;
  while (i < into.size() || j < more.size()) {
    const bool take_into =
        j == more.size() || (i < into.size() && (into[i].a != more[j].a ? into[i].a < more[j].a
                                                                        : into[i].b <= more[j].b));
    if (take_into) {
      if (j < more.size() && into[i].a == more[j].a && into[i].b == more[j].b) ++j;
      merged.push_back(into[i]);
      flags.push_back(into_flags[i]);
      ++i;
    } else {
      merged.push_back(more[j]);
      flags.push_back(more_flags[j]);
      ++j;
    }
  }
  into = std::move(merged);
  into_flags = std::move(flags);
}

int64_t classify_pairs(std::span<const geom::Vec3d> positions, const Topology& topo,
                       std::span<FacePair> pairs, std::vector<uint8_t>& certain, int threads,
                       const geom::PlaneCoefficients* planes) {
  certain.assign(pairs.size(), 1);
  const geom::FilteredPredicates pred{positions.data()};
  int64_t uncertain = 0;
  const auto count = static_cast<int64_t>(pairs.size());
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : uncertain) if (count > 512)
  for (int64_t i = 0; i < count; ++i) {
    // A pair's data is scattered (its second triangle anywhere in the mesh): its test waited on
    // a dozen cache misses, one after another. Ahead of time, the triangles of the pair 16 on,
    // then the planes and corners of the pair 8 on (its triangles by then in cache).
    if (i + 16 < count) {
      __builtin_prefetch(&topo.triangles[pairs[i + 16].a]);
      __builtin_prefetch(&topo.triangles[pairs[i + 16].b]);
    }
    if (i + 8 < count) {
      const FacePair& ahead = pairs[i + 8];
      for (const int32_t face : {ahead.a, ahead.b}) {
        const geom::Tri& t = topo.triangles[face];
        if (planes) __builtin_prefetch(&planes[face]);
        for (int k = 0; k < 3; ++k) __builtin_prefetch(&positions[t.v[k]]);
      }
    }
    FacePair& pair = pairs[i];
    const geom::Tri& f = topo.triangles[pair.a];
    const geom::Tri& x = topo.triangles[pair.b];
    geom::Answer crossing;
    if (planes) {
      uint32_t f_shared, x_shared;
      shared_corners(f, x, f_shared, x_shared);
      geom::Sign sf[3], sx[3];
      sides_against(positions.data(), planes[pair.b], f, f_shared, x, sf);
      sides_against(positions.data(), planes[pair.a], x, x_shared, f, sx);
      crossing = geom::is_crossing_given_sides(pred, f, x, sf, sx);
    } else {
      crossing = geom::is_crossing(pred, f, x);
    }
    if (crossing == geom::Answer::uncertain) {
      certain[i] = 0;
      ++uncertain;
    } else {
      pair.kind = crossing == geom::Answer::yes ? PairKind::crossing : PairKind::touching;
    }
  }
  return uncertain;
}

}  // namespace snag::detect
