// Vertex welding with a uniform grid and union-find. The grid's cell is 2*tol, so two vertices
// within tol of each other fall in the same or adjacent cells even after the rounding of
// x / cell (a cell of exactly tol could put them two cells apart). Union-find always keeps the
// smaller id as the root, so the representative of a cluster is its smallest id whatever the
// order in which pairs are found.
#include "snag/mesh/weld.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>
#include <unordered_map>

#include "snag/error.h"

namespace snag::mesh {
namespace {

class MinRootUnionFind {
 public:
  explicit MinRootUnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }

  int32_t find(int32_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];  // path halving
      i = parent_[i];
    }
    return i;
  }
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a < b)
      parent_[b] = a;
    else if (b < a)
      parent_[a] = b;
  }
  std::vector<int32_t> representatives() {
    std::vector<int32_t> rep(parent_.size());
    for (size_t i = 0; i < rep.size(); ++i) rep[i] = find(static_cast<int32_t>(i));
    return rep;
  }

 private:
  std::vector<int32_t> parent_;
};

/// A grid cell: floor(coordinate / cell) kept as doubles, so that no tolerance, however small
/// against the coordinates, overflows an integer. (+0.0 stands for -0.0 so that equal keys
/// hash equally.)
struct Cell {
  double c[3];
  bool operator==(const Cell& o) const {
    return c[0] == o.c[0] && c[1] == o.c[1] && c[2] == o.c[2];
  }
  bool operator<(const Cell& o) const {
    if (c[0] != o.c[0]) return c[0] < o.c[0];
    if (c[1] != o.c[1]) return c[1] < o.c[1];
    return c[2] < o.c[2];
  }
};

struct CellHash {
  size_t operator()(const Cell& k) const {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (double d : k.c) {
      uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    return static_cast<size_t>(h);
  }
};

bool position_less(const geom::Vec3d& a, const geom::Vec3d& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

/// Vertex ids sorted by position, ties by id.
std::vector<int32_t> sorted_by_position(std::span<const geom::Vec3d> positions) {
  std::vector<int32_t> order(positions.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    if (position_less(positions[a], positions[b])) return true;
    if (position_less(positions[b], positions[a])) return false;
    return a < b;
  });
  return order;
}

}  // namespace

std::vector<int32_t> weld_representatives(std::span<const geom::Vec3d> positions,
                                          double tolerance) {
  if (!(tolerance >= 0) || !std::isfinite(tolerance)) {
    throw UsageError("weld tolerance " + std::to_string(tolerance) +
                     " is not a finite number >= 0");
  }
  const size_t n = positions.size();
  MinRootUnionFind sets(n);
  if (tolerance == 0) {
    const std::vector<int32_t> order = sorted_by_position(positions);
    for (size_t k = 1; k < n; ++k) {
      if (positions[order[k]] == positions[order[k - 1]]) sets.unite(order[k], order[k - 1]);
    }
    return sets.representatives();
  }

  const double cell_size = 2 * tolerance;
  const double tol2 = tolerance * tolerance;
  std::vector<Cell> cells(n);
  for (size_t i = 0; i < n; ++i) {
    const geom::Vec3d& p = positions[i];
    cells[i] = {{std::floor(p.x / cell_size) + 0.0, std::floor(p.y / cell_size) + 0.0,
                 std::floor(p.z / cell_size) + 0.0}};
  }
  // Vertices sorted by cell (ties by id), and each occupied cell's range in that order.
  std::vector<int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    if (cells[a] < cells[b]) return true;
    if (cells[b] < cells[a]) return false;
    return a < b;
  });
  std::unordered_map<Cell, std::pair<size_t, size_t>, CellHash> ranges;
  ranges.reserve(n);
  for (size_t k = 0; k < n;) {
    size_t e = k + 1;
    while (e < n && cells[order[e]] == cells[order[k]]) ++e;
    ranges.emplace(cells[order[k]], std::make_pair(k, e));
    k = e;
  }

  auto close = [&](int32_t a, int32_t b) {
    const geom::Vec3d d = positions[a] - positions[b];
    return geom::dot(d, d) <= tol2;
  };
  // Each unordered pair of neighbouring cells is visited once: the cell itself, then the 13
  // neighbours whose offset is lexicographically positive.
  for (const auto& [cell, range] : ranges) {
    for (size_t a = range.first; a < range.second; ++a) {
      for (size_t b = a + 1; b < range.second; ++b) {
        if (close(order[a], order[b])) sets.unite(order[a], order[b]);
      }
    }
    for (int dx = 0; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0))) continue;
          const Cell other{{cell.c[0] + dx, cell.c[1] + dy, cell.c[2] + dz}};
          // Past 2^53 a neighbour's key rounds back onto the cell itself, already handled.
          if (other == cell) continue;
          const auto it = ranges.find(other);
          if (it == ranges.end()) continue;
          for (size_t a = range.first; a < range.second; ++a) {
            for (size_t b = it->second.first; b < it->second.second; ++b) {
              if (close(order[a], order[b])) sets.unite(order[a], order[b]);
            }
          }
        }
      }
    }
  }
  return sets.representatives();
}

int64_t count_coincident_vertices(std::span<const geom::Vec3d> positions) {
  const std::vector<int32_t> order = sorted_by_position(positions);
  int64_t count = 0;
  for (size_t k = 1; k < order.size(); ++k) {
    if (positions[order[k]] == positions[order[k - 1]]) ++count;
  }
  return count;
}

std::vector<geom::Tri> welded_triangles(std::span<const geom::Tri> triangles,
                                        std::span<const int32_t> representative) {
  std::vector<geom::Tri> welded(triangles.begin(), triangles.end());
  if (representative.empty()) return welded;
  for (geom::Tri& t : welded)
    for (int32_t& v : t.v) v = representative[v];
  return welded;
}

}  // namespace snag::mesh
