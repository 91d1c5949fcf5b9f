#include "snag/detect/pairs.h"

#include <algorithm>

#include "snag/geom/narrow_phase.h"

namespace snag::detect {

std::vector<FacePair> expand_hits(const Topology& topo, std::span<const EdgeTriangleTask> hits,
                                  std::span<const uint8_t> degenerate_flags) {
  std::vector<FacePair> pairs;
  pairs.reserve(hits.size() * 2);
  for (const EdgeTriangleTask& hit : hits) {
    for (int32_t i = topo.edge_face_offsets[hit.edge]; i < topo.edge_face_offsets[hit.edge + 1]; ++i) {
      const int32_t face = topo.edge_faces[i];
      if (face == hit.triangle || degenerate_flags[face]) continue;
      pairs.push_back({std::min(face, hit.triangle), std::max(face, hit.triangle), PairKind::touching});
    }
  }
  auto by_ids = [](const FacePair& x, const FacePair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; };
  std::sort(pairs.begin(), pairs.end(), by_ids);
  pairs.erase(std::unique(pairs.begin(), pairs.end(),
                          [](const FacePair& x, const FacePair& y) { return x.a == y.a && x.b == y.b; }),
              pairs.end());
  return pairs;
}

void merge_pairs(std::vector<FacePair>& into, std::vector<uint8_t>& into_flags, std::span<const FacePair> more,
                 std::span<const uint8_t> more_flags) {
  std::vector<FacePair> merged;
  std::vector<uint8_t> flags;
  merged.reserve(into.size() + more.size());
  flags.reserve(into.size() + more.size());
  size_t i = 0, j = 0;
  while (i < into.size() || j < more.size()) {
    const bool take_into = j == more.size() ||
                           (i < into.size() && (into[i].a != more[j].a ? into[i].a < more[j].a : into[i].b <= more[j].b));
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

int64_t classify_pairs(std::span<const geom::Vec3d> positions, const Topology& topo, std::span<FacePair> pairs,
                       std::vector<uint8_t>& certain, int threads) {
  certain.assign(pairs.size(), 1);
  const geom::FilteredPredicates pred{positions.data()};
  int64_t uncertain = 0;
  const auto count = static_cast<int64_t>(pairs.size());
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : uncertain) if (count > 4096)
  for (int64_t i = 0; i < count; ++i) {
    FacePair& pair = pairs[i];
    const geom::Answer crossing = geom::is_crossing(pred, topo.triangles[pair.a], topo.triangles[pair.b]);
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
