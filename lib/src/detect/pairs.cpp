#include "snag/detect/pairs.h"

#include <algorithm>

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
void sort_unique(std::vector<uint64_t>& keys, int bits) {
  constexpr int kMaxDigit = 12;
  const int passes = (bits + kMaxDigit - 1) / kMaxDigit;
  const int digit = (bits + passes - 1) / passes;
  const size_t buckets = size_t{1} << digit;
  std::vector<uint64_t> scratch(keys.size());
  std::vector<size_t> start(buckets + 1);
  for (int shift = 0; shift < bits; shift += digit) {
    std::fill(start.begin(), start.end(), 0);
    for (uint64_t k : keys) ++start[((k >> shift) & (buckets - 1)) + 1];
    for (size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
    for (uint64_t k : keys) scratch[start[(k >> shift) & (buckets - 1)]++] = k;
    keys.swap(scratch);
  }
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

int bits_for(int64_t count) {
  int bits = 1;
  while ((int64_t{1} << bits) < count) ++bits;
  return bits;
}

}  // namespace

std::vector<FacePair> expand_hits(const Topology& topo, std::span<const EdgeTriangleTask> hits,
                                  std::span<const uint8_t> degenerate_flags) {
  // Pairs packed as a << id_bits | b, so that sorting the keys sorts by (a, b).
  const int id_bits = bits_for(topo.triangle_count());
  std::vector<uint64_t> keys;
  keys.reserve(hits.size() * 2);
  for (const EdgeTriangleTask& hit : hits) {
    for (int32_t i = topo.edge_face_offsets[hit.edge]; i < topo.edge_face_offsets[hit.edge + 1];
         ++i) {
      const int32_t face = topo.edge_faces[i];
      if (face == hit.triangle || degenerate_flags[face]) continue;
      const auto a = static_cast<uint64_t>(std::min(face, hit.triangle));
      const auto b = static_cast<uint64_t>(std::max(face, hit.triangle));
      keys.push_back(a << id_bits | b);
    }
  }
  sort_unique(keys, 2 * id_bits);
  std::vector<FacePair> pairs(keys.size());
  const uint64_t low = (uint64_t{1} << id_bits) - 1;
  for (size_t i = 0; i < keys.size(); ++i)
    pairs[i] = {static_cast<int32_t>(keys[i] >> id_bits), static_cast<int32_t>(keys[i] & low),
                PairKind::touching};
  return pairs;
}

void merge_pairs(std::vector<FacePair>& into, std::vector<uint8_t>& into_flags,
                 std::span<const FacePair> more, std::span<const uint8_t> more_flags) {
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
