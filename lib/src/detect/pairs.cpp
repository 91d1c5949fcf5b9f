#include "snag/detect/pairs.h"

#include <algorithm>
#include <memory>

#include <omp.h>

#include "snag/detect/pair_test.h"
#include "snag/geom/narrow_phase.h"
#include "snag/threads.h"

namespace snag::detect {

namespace {

/// How this file's least-significant-digit radix sorts cut keys of `bits` bits into digits: the
/// fewest passes of digits of at most 12 bits (4,096 counts, 32 KB: in L1 with room to spare),
/// the bits spread evenly over them. Cloth-ball's 34-bit keys take three passes of 12 bits where
/// 11-bit digits took four (expand_hits on its frames 3.1-3.2 -> 2.5-2.8 ms on the 2-core EPYC),
/// 36K's 32-bit keys three of 11 as before.
struct RadixDigits {
  static constexpr int kMaxDigit = 12;
  int passes, digit;
  uint64_t mask;
  explicit RadixDigits(int bits)
      : passes((bits + kMaxDigit - 1) / kMaxDigit),
        digit((bits + passes - 1) / passes),
        mask((uint64_t{1} << digit) - 1) {}
  size_t buckets() const { return static_cast<size_t>(mask) + 1; }
};

/// Sorts and deduplicates keys below 2^bits with a radix sort (RadixDigits), on one thread:
/// linear in the count, where a comparison sort of a frame's hundreds of thousands of hit pairs
/// was a third of the frame. This is sorted_pairs_of_runs' sort for a single run, kept apart:
/// that one with its parallel regions made conditional (`if (pieces > 1)`) still took 2,244
/// triangles' exact + classify from 0.021-0.041 to 0.034-0.050 ms.
void sort_unique(std::vector<uint64_t>& keys, int bits) {
  const RadixDigits radix(bits);
  std::vector<uint64_t> scratch(keys.size());
  std::vector<size_t> start(radix.buckets() + 1);
  for (int shift = 0; shift < bits; shift += radix.digit) {
    std::fill(start.begin(), start.end(), 0);
    for (uint64_t k : keys) ++start[((k >> shift) & radix.mask) + 1];
    for (size_t b = 0; b < radix.buckets(); ++b) start[b + 1] += start[b];
    for (uint64_t k : keys) scratch[start[(k >> shift) & radix.mask]++] = k;
    keys.swap(scratch);
  }
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

/// The pairs of `count` sorted unique keys a << id_bits | b, of kind `touching`.
std::vector<FacePair> pairs_of(const uint64_t* keys, size_t count, int id_bits) {
  std::vector<FacePair> pairs(count);
  const uint64_t low = (uint64_t{1} << id_bits) - 1;
  for (size_t i = 0; i < count; ++i)
    pairs[i] = {static_cast<int32_t>(keys[i] >> id_bits), static_cast<int32_t>(keys[i] & low),
                PairKind::touching};
  return pairs;
}

/// sort_unique of the keys of `runs` joined in order, shared among as many threads as there are
/// runs, then pairs_of. Each pass is cut into as many pieces (the runs themselves in the first
/// pass, so that they are never joined; equal slices after): each piece's digits are counted,
/// then placed after the same digit's keys of the pieces before it, so that every pass is stable
/// and the result is the same for any number of runs. A piece is any thread's, so a team smaller
/// than asked for (OMP_THREAD_LIMIT, nesting) still takes every one.
std::vector<FacePair> sorted_pairs_of_runs(const std::vector<std::vector<uint64_t>>& runs,
                                           int id_bits) {
  const int bits = 2 * id_bits;
  const RadixDigits radix(bits);
  const size_t buckets = radix.buckets();
  const int pieces = static_cast<int>(runs.size());
  int64_t total = 0;
  for (const std::vector<uint64_t>& run : runs) total += static_cast<int64_t>(run.size());
  // The passes go from one buffer to the other; each is written whole before it is read, so
  // neither is zeroed first.
  std::unique_ptr<uint64_t[]> buffer[2] = {std::make_unique_for_overwrite<uint64_t[]>(total),
                                           std::make_unique_for_overwrite<uint64_t[]>(total)};
  std::vector<int64_t> start(static_cast<size_t>(pieces) * buckets);  // [piece][digit]
#pragma omp parallel num_threads(pieces)
  {
    const int t = omp_get_thread_num(), team = omp_get_num_threads();
    for (int pass = 0; pass < radix.passes; ++pass) {
      const int shift = pass * radix.digit;
      const uint64_t* const from = pass == 0 ? nullptr : buffer[(pass - 1) & 1].get();
      uint64_t* const to = buffer[pass & 1].get();
      // Piece q's keys: run q in the first pass, else the q-th slice of the last pass's output.
      auto piece = [&](int q) {
        if (pass == 0) return std::span<const uint64_t>(runs[static_cast<size_t>(q)]);
        const int64_t first = total * q / pieces, last = total * (q + 1) / pieces;
        return std::span<const uint64_t>(from + first, static_cast<size_t>(last - first));
      };
      for (int q = t; q < pieces; q += team) {
        int64_t* const counts = start.data() + static_cast<size_t>(q) * buckets;
        std::fill(counts, counts + buckets, 0);
        for (const uint64_t k : piece(q)) ++counts[(k >> shift) & radix.mask];
      }
#pragma omp barrier
#pragma omp single
      {
        int64_t at = 0;
        for (size_t b = 0; b < buckets; ++b)
          for (int q = 0; q < pieces; ++q) {
            int64_t& slot = start[static_cast<size_t>(q) * buckets + b];
            const int64_t count = slot;
            slot = at;
            at += count;
          }
      }  // the single's closing barrier: every piece's starts are set
      for (int q = t; q < pieces; q += team) {
        int64_t* const next = start.data() + static_cast<size_t>(q) * buckets;
        for (const uint64_t k : piece(q)) to[next[(k >> shift) & radix.mask]++] = k;
      }
#pragma omp barrier
    }
  }
  uint64_t* const sorted = buffer[(radix.passes - 1) & 1].get();
  const auto count = static_cast<size_t>(std::unique(sorted, sorted + total) - sorted);
  return pairs_of(sorted, count, id_bits);
}

int bits_for(int64_t count) {
  int bits = 1;
  while ((int64_t{1} << bits) < count) ++bits;
  return bits;
}

}  // namespace

std::vector<FacePair> expand_hits(const Topology& topo, std::span<const EdgeTriangleTask> hits,
                                  std::span<const uint8_t> degenerate_flags, int threads) {
  // Pairs packed as a << id_bits | b, so that sorting the keys sorts by (a, b).
  const int id_bits = bits_for(topo.triangle_count());
  const auto hit_count = static_cast<int64_t>(hits.size());
  // The keys of hits [first, last), appended to `out`.
  auto list_keys = [&](int64_t first, int64_t last, std::vector<uint64_t>& out) {
    out.reserve(out.size() + static_cast<size_t>(last - first) * 2);
    for (int64_t h = first; h < last; ++h) {
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
  // A run of hits per thread, of at least kHitsPerThread: below that, one thread without a
  // parallel region (which cost ~15 us a frame at 2,244 triangles).
  constexpr int64_t kHitsPerThread = 8192;
  const int runs =
      static_cast<int>(std::clamp<int64_t>(hit_count / kHitsPerThread, 1, thread_count(threads)));
  if (runs == 1) {
    std::vector<uint64_t> keys;
    list_keys(0, hit_count, keys);
    sort_unique(keys, 2 * id_bits);
    return pairs_of(keys.data(), keys.size(), id_bits);
  }
  std::vector<std::vector<uint64_t>> run_keys(static_cast<size_t>(runs));
#pragma omp parallel num_threads(runs)
  for (int r = omp_get_thread_num(); r < runs; r += omp_get_num_threads())
    list_keys(hit_count * r / runs, hit_count * (r + 1) / runs, run_keys[static_cast<size_t>(r)]);
  return sorted_pairs_of_runs(run_keys, id_bits);
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
  const auto count = static_cast<int64_t>(pairs.size());
  for_each_index(threads, count, 512, [&](int64_t i) {
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
    if (crossing == geom::Answer::uncertain)
      certain[i] = 0;
    else
      pair.kind = crossing == geom::Answer::yes ? PairKind::crossing : PairKind::touching;
  });
  return std::count(certain.begin(), certain.end(), uint8_t{0});
}

}  // namespace snag::detect
